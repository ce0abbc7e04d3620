"""Robustness benchmark: bad inputs, faulty FMUs and interruptions against the ``twin`` CLI, and a
calibration whose evaluations crash and hang.

Part 1 runs each case as a user would, in a fresh process (``twin ...``), and sorts the outcome:

* ``ok``: what the case expects happened (a typed ``twin: error:`` line naming the value, a
  clean interruption with exit 130, or a correct result for the good cases);
* ``traceback``: a Python traceback, or the CLI's "internal error" line (a bug reached the last
  line of defence);
* ``native crash``: the process died by a signal, or ended non-zero with no ``twin: error:``;
* ``silent wrong``: exit 0 (or a result written) where the input was bad, or a good case whose
  result is missing or incomplete;
* ``damaged``: an earlier complete result changed, or a temporary file was left beside it;
* ``hang``: no exit within the case's time limit;
* ``unclear``: a typed error that does not name what the case expects it to name.

Part 2 calibrates the gearbox FMU (NSGA-II, real evaluations in worker processes) twice: with
one evaluation in ten segfaulting and one in twenty hanging, chosen by a hash of the
evaluation's parameters, and with those same evaluations raising an ordinary error instead.
Both runs must finish and agree on every evaluation and on the result.

Usage::

    python bench/robustness.py [--work DIR] [--skip-calibration] [--json results.json]
"""
from __future__ import annotations

import argparse
import ctypes
import hashlib
import json
import math
import os
import platform
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
TWIN = [sys.executable, "-m", "twin.cli"]
CATEGORIES = ("ok", "traceback", "native crash", "silent wrong", "damaged", "hang", "unclear")


# ----------------------------------------------------------------------------------------------
# Part 1: cases

@dataclass
class Case:
    """One CLI invocation and what it must do.

    expect: "error" (exit 2, one ``twin: error:`` line containing every string of ``names``),
    "ok" (exit 0; ``result`` exists and is a complete result), "interrupt" (exit 130 after
    ``signal_after`` seconds of ``send``), "killed" (SIGKILL after ``signal_after`` s: nothing
    to check but the guard).
    guard: a complete earlier result that must come out byte-identical.
    """

    name: str
    kind: str
    args: list[str]
    expect: str = "error"
    names: tuple[str, ...] = ()
    result: str | None = None
    guard: str | None = None
    send: int | None = None
    signal_after: float = 0.0
    signals: int = 1
    limit: float = 120.0
    setup: object = None
    env: dict = field(default_factory=dict)


def sha(path: Path) -> str | None:
    return hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() else None


def run_case(case: Case, work: Path) -> tuple[str, str]:
    """Run ``case``; return (category, detail)."""
    if case.setup is not None:
        case.setup(work)
    guard = work / case.guard if case.guard else None
    before = sha(guard) if guard else None
    if guard is not None and before is None:
        return "silent wrong", f"guard {guard} missing before the case"
    env = {**os.environ, "PYTHONPATH": str(REPO), **case.env}
    env.pop("TWIN_DEBUG", None)
    t0 = time.monotonic()
    proc = subprocess.Popen(TWIN + case.args, cwd=work, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=env, start_new_session=True)
    if case.send is not None:
        time.sleep(case.signal_after)
        for k in range(case.signals):
            if proc.poll() is None:
                os.kill(proc.pid, case.send)
            time.sleep(0.5)
    try:
        out, err = proc.communicate(timeout=case.limit)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.communicate()
        return "hang", f"no exit within {case.limit:g} s"
    finally:
        # a killed parent must not leave FMU workers behind
        with_contextlib_kill(proc.pid)
    wall = time.monotonic() - t0
    code = proc.returncode
    if guard is not None:
        if sha(guard) != before:
            return "damaged", f"{case.guard} changed"
        strays = [p.name for p in guard.parent.glob(f".{guard.name}.*.tmp")]
        if strays and case.expect != "killed":
            return "damaged", f"temporary files left: {strays}"
    if "Traceback (most recent call last)" in err or "internal error" in err:
        return "traceback", err.strip().splitlines()[-1][:200]
    if case.expect == "killed":
        return "ok", f"killed after {case.signal_after:g} s"
    if code < 0:
        return "native crash", f"killed by {signal.Signals(-code).name}, stderr {err.strip()[:120]!r}"
    if code not in (0, 2, 130) or (code != 0 and ": error:" not in err and "twin: interrupted" not in err):
        return "native crash", f"exit {code} without a message: {err.strip()[:160]!r}"
    if case.expect == "error":
        if code == 0:
            return "silent wrong", f"exit 0 for bad input; stdout {out.strip()[:120]!r}"
        # ours ("twin: error: ...") or argparse's usage error ("twin simulate: error: ...")
        line = next((ln for ln in err.splitlines() if ln.startswith("twin") and ": error:" in ln), "")
        missing = [n for n in case.names if n.lower() not in err.lower()]
        if code != 2 or not line:
            return "native crash", f"exit {code}: {err.strip()[:160]!r}"
        if missing:
            return "unclear", f"{line[:160]!r} does not name {missing}"
        return "ok", line[:200]
    if case.expect == "interrupt":
        if code != 130:
            return "silent wrong", f"exit {code} after the interrupt: {err.strip()[-160:]!r}"
        return "ok", f"exit 130 in {wall:.1f} s"
    # expect ok
    if code != 0:
        return "silent wrong", f"good input failed with exit {code}: {err.strip()[-200:]!r}"
    if case.result is not None and not result_complete(work / case.result):
        return "silent wrong", f"{case.result} missing or incomplete"
    return "ok", out.strip().splitlines()[-1][:160] if out.strip() else "exit 0"


def with_contextlib_kill(pgid: int) -> None:
    try:
        os.killpg(pgid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass


def result_complete(path: Path) -> bool:
    import h5py
    if not path.is_file():
        return False
    if path.suffix == ".csv":
        return path.stat().st_size > 0
    try:
        with h5py.File(path, "r") as f:
            return bool(f.attrs.get("complete", True)) and len(f.keys()) > 0
    except OSError:
        return False


# ----------------------------------------------------------------------------------------------
# fixtures of the cases

def prepare(work: Path) -> dict[str, Path]:
    """Build the FMUs and write the files the cases use into ``work``."""
    sys.path.insert(0, str(REPO / "tests" / "robustness" / "faulty"))
    from build_faulty import build_faulty

    from fmu_build import build_fmu
    fmus = {"gearbox": build_fmu("GearTwin.Gearbox21", REPO / "modelica", work / "fmus")}
    fmus.update(build_faulty(work / "fmus"))
    gb = fmus["gearbox"]
    scen = work / "scen"
    scen.mkdir(exist_ok=True)

    def scenario(name: str, body: str, *, fmu: Path = gb, stop: float = 0.2) -> Path:
        p = scen / f"{name}.yaml"
        p.write_text(f"version: 1\nname: {name}\nfmu: {fmu}\nstop_time: {stop}\ncommunication_step: 0.01\n"
                     "output: {sample_rate: 100000, variables: [accel_pinion_casing, mesh_force]}\n"
                     "operating: {speed: {constant: 20}, load: {constant: 20}}\n" + body)
        return p

    scenario("good", "")
    scenario("deg", "degradation: {model: pitting, max_increment: 0.02, stop: {pitting_density: 0.06}, "
                    "max_updates: 60, load_window: 0.1, record_duration: 0.05}\n")
    scenario("deg_other", "degradation: {model: pitting, max_increment: 0.03, stop: {pitting_density: 0.06}, "
                          "max_updates: 60, load_window: 0.1, record_duration: 0.05}\n")
    scenario("long", "", stop=60.0)
    scenario("resdeg", "degradation: {model: pitting, max_increment: 0.002, stop: {pitting_density: 0.03}, "
                       "max_updates: 400, load_window: 0.1, record_duration: 0.05}\n")
    scenario("longdeg", "degradation: {model: pitting, max_increment: 0.002, stop: {pitting_density: 0.2}, "
                        "max_updates: 400, load_window: 0.1, record_duration: 0.05}\n")
    (scen / "faulty.yaml").write_text(
        f"version: 1\nname: faulty\nfmu: {fmus['faulty']}\nstop_time: 0.2\ncommunication_step: 0.01\n"
        "output: {sample_rate: 1000}\nparameters: {fault: 1, fault_time: 0.05}\n")
    # measurements: the twin's own healthy run as a record (plumbing only)
    import numpy as np

    from twin.measurements import Record, write_measurements
    from twin.operating import simulate_operating_point
    x = simulate_operating_point(gb, 20.0, 20.0, settle=0.1, duration=0.6, channels=["accel_pinion_casing"])[:, 0]
    x = x + 0.05 * np.std(x) * np.random.default_rng(0).standard_normal(x.size)
    write_measurements([Record("r", {"accel_pinion_casing": x}, {"accel_pinion_casing": "m/s2"}, 1e5,
                               nominal_speed=20.0, load=20.0)], work / "meas.h5")
    write_measurements([Record("r", {"accel_pinion_casing": x[:3]}, {"accel_pinion_casing": "m/s2"}, 1e5,
                               nominal_speed=20.0, load=20.0)], work / "short.h5")
    cal = ("calibration: {parameters: {kt12: [1000, 2500]}, algorithm: nsga2, pop_size: 4, n_gen: 1, "
           "natural_frequencies: [22, 87, 218, 430, 512, 767, 1248, 1927], record_duration: 0.2, "
           "settle_time: 0.05, refine: false}\nexecutor: {type: local, workers: 1}\n")
    scenario("cal", cal)
    scenario("cal_unknown", cal.replace("kt12: [1000, 2500]", "no_such_parameter: [1, 2]"))
    scenario("cal_negative", cal.replace("kt12: [1000, 2500]", "kt12: [-1000, 2500]"))
    scenario("cal_other", cal.replace("kt12: [1000, 2500]", "kt12: [1200, 2500]"))
    (work / "corrupt.h5").write_bytes(b"\x89HDF\r\n\x1a\n" + os.urandom(2000))
    (work / "text.h5").write_text("this is not HDF5\n")
    (work / "dir.h5").mkdir(exist_ok=True)
    (work / "a_file").write_text("x")
    (work / "notzip.fmu").write_text("not a zip")
    import zipfile
    with zipfile.ZipFile(work / "empty.fmu", "w") as z:
        z.writestr("readme.txt", "no model description")
    (work / "binary.yaml").write_bytes(os.urandom(300))
    (work / "empty.yaml").write_text("")
    (work / "list.yaml").write_text("- 1\n- 2\n")
    (work / "notyaml.yaml").write_text("version: 1\nname: [unclosed\n")
    (work / "ro").mkdir(exist_ok=True)
    return fmus


def cases(work: Path, fmus: dict[str, Path]) -> list[Case]:
    gb, faulty = str(fmus["gearbox"]), str(fmus["faulty"])
    S = "scen/"
    out: list[Case] = []

    def sim(name, extra, names=(), expect="error", kind="bad input", result=None, **kw):
        out.append(Case(name, kind, ["simulate", kw.pop("fmu", gb), "--no-progress", *extra], expect, names,
                        result, **kw))

    # -- twin simulate: times ------------------------------------------------------------------
    for v, names in (("nan", ("nan",)), ("inf", ("inf",)), ("-inf", ("inf",)), ("1e12", ("memory",)),
                     ("-1", ("-1",)), ("0", ("0",))):
        sim(f"simulate --stop-time {v}", [f"--stop-time={v}", "--output", "s.h5"], names)
    sim("simulate --stop-time -inf (as a separate word)", ["--stop-time", "-inf", "--output", "s.h5"],
        ("--stop-time",))
    sim("simulate --stop-time 1e-7 (no sample)", ["--stop-time", "1e-7", "--output", "s.h5"], ("1e-07",))
    sim("simulate --start-time after --stop-time", ["--start-time", "0.5", "--stop-time", "0.1", "--output", "s.h5"],
        ("0.5",))
    sim("simulate --start-time nan", ["--start-time", "nan", "--stop-time", "0.1", "--output", "s.h5"], ("nan",))
    for v in ("0", "-1e-5", "nan", "inf"):
        sim(f"simulate --output-interval {v}", ["--stop-time", "0.1", f"--output-interval={v}", "--output", "s.h5"],
            (v.replace("-1e-5", "-1e-05"),))
    sim("simulate stop time not a multiple of the interval", ["--stop-time", "0.100005", "--output", "s.h5"],
        ("whole number",))
    sim("simulate 1e5 s at 100 kHz names the memory", ["--stop-time", "1e5", "--output", "s.h5"], ("memory", "TiB"))
    # -- twin simulate: paths ------------------------------------------------------------------
    sim("simulate output in a missing directory", ["--stop-time", "0.01", "--output", "nodir/s.h5"], ("nodir",))
    sim("simulate output is a directory", ["--stop-time", "0.01", "--output", "dir.h5"], ("dir.h5",))
    sim("simulate output in an unwritable directory", ["--stop-time", "0.01", "--output", "/sys/s.h5"], ("/sys",))
    sim("simulate output in an immutable directory", ["--stop-time", "0.01", "--output", "ro/s.h5"], ("ro",),
        setup=lambda w: subprocess.run(["chattr", "+i", str(w / "ro")], capture_output=True))
    sim("simulate output with an unknown suffix", ["--stop-time", "0.01", "--output", "s.mat"], (".mat",))
    sim("simulate a missing FMU", ["--stop-time", "0.01", "--output", "s.h5"], ("missing.fmu",), fmu="missing.fmu")
    sim("simulate an FMU that is a directory", ["--stop-time", "0.01", "--output", "s.h5"], ("dir.h5",),
        fmu="dir.h5")
    sim("simulate an FMU that is not a zip", ["--stop-time", "0.01", "--output", "s.h5"], ("notzip.fmu",),
        fmu="notzip.fmu")
    sim("simulate a zip without modelDescription.xml", ["--stop-time", "0.01", "--output", "s.h5"],
        ("empty.fmu",), fmu="empty.fmu")
    sim("simulate an FMU whose GUID does not match (fmi2Instantiate returns NULL)",
        ["--stop-time", "0.01", "--output", "s.h5"], ("fmi2Instantiate",), fmu=str(fmus["wrong_guid"]))
    sim("simulate an FMU with a truncated binary", ["--stop-time", "0.01", "--output", "s.h5"], ("Faulty",),
        fmu=str(fmus["truncated"]))
    # -- twin simulate: parameters and inputs ----------------------------------------------------
    for tok, names in (("no_such=1", ("no_such",)), ("c_mesh=nan", ("c_mesh",)), ("c_mesh=-1e9", ("c_mesh", "negative")),
                       ("m5=0", ("m5",)), ("kt12=-5", ("kt12",)), ("mesh_stiffness_scale=-2", ("mesh_stiffness_scale",)),
                       ("load_torque=5", ("load_torque", "input")), ("accel_pinion_casing=1", ("accel_pinion_casing",)),
                       ("c_mesh", ("c_mesh",)), ("c_mesh=abc", ("abc",))):
        sim(f"simulate --param {tok}", ["--stop-time", "0.01", "--output", "s.h5", "--param", tok], names)
    for tok, names in (("c_mesh=3", ("c_mesh", "parameter")), ("accel_pinion_casing=1", ("accel_pinion_casing",)),
                       ("nope=1", ("nope",)), ("load_torque=inf", ("load_torque",))):
        sim(f"simulate --input {tok}", ["--stop-time", "0.01", "--output", "s.h5", "--input", tok], names)
    sim("simulate --outputs unknown", ["--stop-time", "0.01", "--output", "s.h5", "--outputs", "nope"], ("nope",))
    sim("simulate mesh_stiffness_scale=1e6 (gears separate)",
        ["--stop-time", "0.2", "--output", "s.h5", "--param", "mesh_stiffness_scale=1e6", "--input",
         "load_torque=20", "--input", "motor_speed_ref=125.66"], ("implausible",))
    # -- faulty FMUs ---------------------------------------------------------------------------
    for mode, names in ((1, ("SIGSEGV",)), (2, ("status 3",)), (4, ("SIGABRT",)), (5, ("on purpose",)),
                        (6, ("fatal",))):
        sim(f"simulate FMU fault {mode}", ["--stop-time", "0.1", "--output-interval", "0.01", "--output", "f.h5",
                                           "--param", f"fault={mode}"], names, kind="faulty FMU", fmu=faulty,
            guard="f_guard.h5")
    sim("simulate FMU that hangs, --timeout 3", ["--stop-time", "0.1", "--output-interval", "0.01", "--output",
                                                 "f.h5", "--param", "fault=3", "--timeout", "3"], ("3 s",),
        kind="faulty FMU", fmu=faulty, guard="f_guard.h5", limit=60)
    sim("simulate FMU that hangs, Ctrl-C twice", ["--stop-time", "0.1", "--output-interval", "0.01", "--output",
                                                  "f.h5", "--param", "fault=3"], expect="interrupt",
        kind="interruption", fmu=faulty, guard="f_guard.h5", send=signal.SIGINT, signal_after=3, signals=2, limit=60)
    out.append(Case("run scenario on a segfaulting FMU", "faulty FMU", ["run", S + "faulty.yaml", "--output", "f.h5",
                                                                      "--no-progress"], names=("SIGSEGV",),
                    guard="f_guard.h5"))
    # -- twin run: scenario files ----------------------------------------------------------------
    def run(name, scen_file, extra=(), names=(), expect="error", kind="bad scenario", result=None, guard=None, **kw):
        out.append(Case(name, kind, ["run", scen_file, "--no-progress", *extra], expect, names, result, guard, **kw))

    run("run a missing scenario", "nope.yaml", ["--output", "r.h5"], ("nope.yaml",))
    run("run a scenario that is a directory", "dir.h5", ["--output", "r.h5"], ("dir.h5", "directory"))
    run("run a binary file", "binary.yaml", ["--output", "r.h5"], ("binary.yaml",))
    run("run an empty scenario", "empty.yaml", ["--output", "r.h5"], ("empty.yaml",))
    run("run a YAML list", "list.yaml", ["--output", "r.h5"], ("list.yaml",))
    run("run invalid YAML", "notyaml.yaml", ["--output", "r.h5"], ("notyaml.yaml",))
    edits = {
        "duplicate key": ("stop_time: 0.2\nstop_time: 0.3\n", ("duplicate", "stop_time")),
        "stop_time .nan": ("stop_time: .nan\n", ("stop_time", "finite")),
        "stop_time .inf": ("stop_time: .inf\n", ("stop_time", "finite")),
        "stop_time 1e12": ("stop_time: 1.0e12\n", ("stop_time", "memory")),
        "communication_step .nan": ("communication_step: .nan\n", ("communication_step", "finite")),
        "communication_step .inf": ("communication_step: .inf\n", ("communication_step",)),
        "sample_rate .nan": ("output: {sample_rate: .nan}\n", ("sample_rate", "finite")),
        "sample_rate .inf": ("output: {sample_rate: .inf}\n", ("sample_rate",)),
        "step longer than the run": ("communication_step: 0.5\n", ("communication_step",)),
        "step not dividing the run": ("communication_step: 0.03\n", ("communication_step", "whole number")),
        "negative damping": ("parameters: {c_mesh: -1.0e9}\n", ("c_mesh", "negative")),
        "negative stiffness": ("parameters: {kx45: -1.0e8}\n", ("kx45", "negative")),
        "zero mass": ("parameters: {m5: 0}\n", ("m5",)),
        "mesh_stiffness_scale 1e6": ("parameters: {mesh_stiffness_scale: 1.0e6}\n", ("implausible",)),
        "unknown parameter": ("parameters: {no_such: 1}\n", ("no_such",)),
        "unknown key": ("colour: blue\n", ("colour",)),
        "missing FMU file": ("fmu: /nonexistent/x.fmu\n", ("x.fmu",)),
        "parameter as string": ("parameters: {c_mesh: lots}\n", ("c_mesh",)),
        "event off the step grid": ("events: [{time: 0.015, override: {c_mesh: 1000}}]\n", ("events",)),
        "event after stop": ("events: [{time: 5.0, override: {c_mesh: 1000}}]\n", ("events",)),
    }
    base = (work / "scen" / "good.yaml").read_text()
    for label, (text, names) in edits.items():
        key = text.split(":")[0]
        lines = [ln for ln in base.splitlines(keepends=True)
                 if not ln.startswith(key + ":") or label == "duplicate key"]
        if label == "duplicate key":
            lines = [ln for ln in lines if not ln.startswith("stop_time:")]
        if key == "output":
            text = text.replace("}", ", variables: [accel_pinion_casing]}")
        body = "".join(lines) + text
        fname = f"scen/bad_{label.replace(' ', '_').replace('.', '')}.yaml"

        def write(w, fname=fname, body=body):
            (w / fname).write_text(body)
        run(f"run scenario with {label}", fname, ["--output", "r.h5"], names, setup=write, guard="guard.h5")
    for v, names in (("nan", ("nan",)), ("inf", ("inf",)), ("1e12", ("memory",)), ("1e5", ("memory",)),
                     ("-1", ("stop_time",)), ("0.205", ("whole number",))):
        run(f"run --stop-time {v}", S + "good.yaml", ["--output", "guard.h5", "--stop-time", v], names,
            guard="guard.h5")
    run("run output in a missing directory", S + "good.yaml", ["--output", "nodir/r.h5"], ("nodir",))
    run("run output is a directory", S + "good.yaml", ["--output", "dir.h5"], ("dir.h5",))
    run("run output in an unwritable directory", S + "good.yaml", ["--output", "/sys/r.h5"], ("/sys",))
    run("run output with an unknown suffix", S + "good.yaml", ["--output", "r.txt"], (".txt",))
    run("run --resume on a plain run", S + "good.yaml", ["--output", "guard.h5", "--resume"], ("resume",),
        guard="guard.h5")
    # -- resume identity -----------------------------------------------------------------------
    def foreign_partial(w):
        shutil.copy(w / "deg_other_done.h5", w / "dg.partial.h5")

    def corrupt_partial(w):
        shutil.copy(w / "corrupt.h5", w / "dg.partial.h5")

    def text_partial(w):
        shutil.copy(w / "text.h5", w / "dg.partial.h5")
    run("run --resume from another scenario's partial output", S + "deg.yaml", ["--output", "dg.h5", "--resume"],
        ("another scenario",), kind="resume", setup=foreign_partial, guard="dg.h5")
    run("run --resume from a corrupt partial HDF5", S + "deg.yaml", ["--output", "dg.h5", "--resume"],
        ("dg.partial.h5",), kind="resume", setup=corrupt_partial, guard="dg.h5")
    run("run --resume from a text file", S + "deg.yaml", ["--output", "dg.h5", "--resume"],
        ("dg.partial.h5",), kind="resume", setup=text_partial, guard="dg.h5")
    # -- interruptions -------------------------------------------------------------------------
    run("SIGINT during a plain run over a complete result", S + "long.yaml", ["--output", "guard.h5"],
        expect="interrupt", kind="interruption", guard="guard.h5", send=signal.SIGINT, signal_after=3.0)
    run("SIGKILL during a plain run over a complete result", S + "long.yaml", ["--output", "guard.h5"],
        expect="killed", kind="interruption", guard="guard.h5", send=signal.SIGKILL, signal_after=3.0)
    run("run after a SIGKILL leaves no temporary file", S + "good.yaml", ["--output", "guard2.h5"], expect="ok",
        kind="good", result="guard2.h5")
    for k in range(8):
        run(f"SIGINT during a degradation run over a complete result (try {k + 1})", S + "longdeg.yaml",
            ["--output", "dg_guard.h5"], expect="interrupt", kind="interruption", guard="dg_guard.h5",
            send=signal.SIGINT, signal_after=5.0 + 1.0 * k)
    run("SIGKILL during a degradation run over a complete result", S + "longdeg.yaml", ["--output", "dg_guard.h5"],
        expect="killed", kind="interruption", guard="dg_guard.h5", send=signal.SIGKILL, signal_after=4.0)
    out.append(Case("SIGINT to calibrate", "interruption", ["calibrate", S + "cal.yaml", "--measurements", "meas.h5",
                                                            "--out", "cal_int", "--no-progress"], "interrupt",
                    send=signal.SIGINT, signal_after=6.0, limit=120))
    # -- measurements, comparison, calibration -----------------------------------------------------
    def cmp(name, meas, extra=(), names=(), kind="bad measurement"):
        out.append(Case(name, kind, ["compare", S + "good.yaml", "--measurements", meas, "--out", "rep", *extra],
                        "error", names))
    cmp("compare a corrupt HDF5", "corrupt.h5", names=("corrupt.h5",))
    cmp("compare a text file named .h5", "text.h5", names=("text.h5",))
    cmp("compare a directory", "dir.h5", names=("dir.h5",))
    cmp("compare a missing file", "nope.h5", names=("nope.h5",))
    cmp("compare a 3-sample record", "short.h5", names=("short.h5", "samples"))
    cmp("compare an unknown record", "meas.h5", ["--record", "nope"], names=("nope",))
    cmp("compare --duration nan", "meas.h5", ["--duration", "nan"], names=("nan",))
    cmp("compare --duration longer than the record", "meas.h5", ["--duration", "100"], names=("100",))
    out.append(Case("compare into an output path that is a file", "bad path",
                    ["compare", S + "good.yaml", "--measurements", "meas.h5", "--out", "a_file"], "error", ("a_file",)))

    def cal(name, scen_file, extra=(), names=(), kind="bad calibration", setup=None):
        out.append(Case(name, kind, ["calibrate", scen_file, "--measurements", "meas.h5", "--no-progress", *extra],
                        "error", names, setup=setup))
    cal("calibrate --out naming a file", S + "cal.yaml", ["--out", "a_file"], ("a_file",))
    cal("calibrate --out in a missing directory", S + "cal.yaml", ["--out", "nodir/cal"], ("nodir",))
    cal("calibrate --out in an unwritable directory", S + "cal.yaml", ["--out", "/sys/cal"], ("/sys",))
    cal("calibrate an unknown parameter", S + "cal_unknown.yaml", ["--out", "cal_u"], ("no_such_parameter",))
    cal("calibrate with a negative stiffness bound", S + "cal_negative.yaml", ["--out", "cal_n"], ("kt12", "negative"))
    cal("calibrate a corrupt measurement", S + "cal.yaml", ["--out", "cal_c"], ("corrupt.h5",))
    out[-1].args[3] = "corrupt.h5"
    cal("calibrate a 3-sample record", S + "cal.yaml", ["--out", "cal_s"], ("short.h5",))
    out[-1].args[3] = "short.h5"

    def truncated_checkpoint(w):
        (w / "cal_t").mkdir(exist_ok=True)
        (w / "cal_t" / "checkpoint.json").write_text('{"algorithm": "nsga2", "generation": 1, "hist')
    cal("calibrate --resume from a truncated checkpoint", S + "cal.yaml", ["--out", "cal_t", "--resume"],
        ("checkpoint.json",), setup=truncated_checkpoint)

    def foreign_checkpoint(w):
        (w / "cal_f").mkdir(exist_ok=True)
        shutil.copy(w / "cal_done" / "checkpoint.json", w / "cal_f" / "checkpoint.json")
    cal("calibrate --resume with changed bounds", S + "cal_other.yaml", ["--out", "cal_f", "--resume"],
        ("checkpoint",), setup=foreign_checkpoint)
    cal("calibrate --workers 0", S + "cal.yaml", ["--out", "cal_w", "--workers", "0"], ("workers",))
    # -- other commands ------------------------------------------------------------------------
    out.append(Case("import a missing CSV", "bad measurement", ["import", "nope.csv", "--out", "m.h5"], "error",
                    ("nope.csv",)))
    out.append(Case("import into a directory", "bad path", ["import", "a_file", "--out", "dir.h5"], "error",
                    ("dir.h5",)))
    out.append(Case("info on a missing FMU", "bad input", ["info", "nope.fmu", "--no-modes"], "error", ("nope.fmu",)))
    # info describes the model description and does not load the binary (like fmpy info): exit 0
    out.append(Case("info on a truncated binary describes its model description", "good",
                    ["info", str(fmus["truncated"])], "ok"))
    out.append(Case("archive without an archive block", "bad scenario", ["archive", S + "good.yaml"], "error",
                    ("archive",)))
    out.append(Case("build an unknown model", "bad input", ["build", "No.Such.Model", "--out", "b",
                                                            "--modelica-dir", str(REPO / "modelica")], "error",
                    ("No.Such.Model",)))
    out.append(Case("build from a missing Modelica directory", "bad path", ["build", "--modelica-dir", "nope"],
                    "error", ("nope",)))
    # -- good inputs ---------------------------------------------------------------------------
    sim("simulate a good run", ["--stop-time", "0.05", "--output", "good.h5"], expect="ok", kind="good",
        result="good.h5")
    sim("simulate a good run to CSV", ["--stop-time", "0.01", "--output", "good.csv"], expect="ok", kind="good",
        result="good.csv")
    sim("simulate the faulty FMU without a fault", ["--stop-time", "0.1", "--output-interval", "0.01", "--output",
                                                    "f_ok.h5"], expect="ok", kind="good", result="f_ok.h5", fmu=faulty)
    run("run a good scenario", S + "good.yaml", ["--output", "good_run.h5"], expect="ok", kind="good",
        result="good_run.h5")
    run("run a good scenario with a 1.0e6-style number", S + "good.yaml", ["--output", "good_run2.h5",
                                                                           "--stop-time", "1.0e-1"],
        expect="ok", kind="good", result="good_run2.h5")
    run("run a degradation", S + "deg.yaml", ["--output", "deg_good.h5"], expect="ok", kind="good",
        result="deg_good.h5", limit=300)
    run("resume a degradation after SIGINT", S + "resdeg.yaml", ["--output", "dg_resume.h5"], expect="interrupt",
        kind="interruption", send=signal.SIGINT, signal_after=6.0)
    run("resume it", S + "resdeg.yaml", ["--output", "dg_resume.h5", "--resume"], expect="ok", kind="good",
        result="dg_resume.h5", limit=600)
    out.append(Case("compare a good record", "good", ["compare", S + "good.yaml", "--measurements", "meas.h5",
                                                      "--out", "rep_ok"], "ok"))
    return out


def make_guards(work: Path) -> None:
    """Complete earlier results that the bad cases must leave untouched."""
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    for scen, out in (("scen/good.yaml", "guard.h5"), ("scen/deg.yaml", "dg.h5"),
                      ("scen/deg_other.yaml", "deg_other_done.h5")):
        subprocess.run(TWIN + ["run", scen, "--output", out, "--no-progress"],
                       cwd=work, env=env, check=True, capture_output=True)
    shutil.copy(work / "guard.h5", work / "f_guard.h5")
    shutil.copy(work / "dg.h5", work / "dg_guard.h5")
    subprocess.run(TWIN + ["calibrate", "scen/cal.yaml", "--measurements", "meas.h5", "--out", "cal_done",
                           "--no-progress"], cwd=work, env=env, check=True, capture_output=True)


# ----------------------------------------------------------------------------------------------
# Part 2: a calibration with crashing and hanging evaluations

def _fault_of(task) -> str | None:
    """'segfault' for one parameter set in ten, 'hang' for one in twenty, by a hash of the values."""
    key = json.dumps(sorted((k, round(float(v), 9)) for k, v in task.parameters.items()))
    u = int(hashlib.sha256(key.encode()).hexdigest()[:8], 16) / 2 ** 32
    return "segfault" if u < 0.10 else "hang" if u < 0.15 else None


def faulty_evaluate(task):
    """The real evaluation, except that the chosen ones crash the worker or never return."""
    from twin.calibration.problem import evaluate_candidate
    fault = _fault_of(task)
    if fault == "segfault":
        ctypes.string_at(0)                   # a real SIGSEGV in native code
    if fault == "hang":
        while True:
            time.sleep(3600)
    return evaluate_candidate(task)


def reference_evaluate(task):
    """The real evaluation, except that the same ones fail with an ordinary, reported error."""
    from twin.calibration.problem import evaluate_candidate
    from twin.errors import SimulationError
    fault = _fault_of(task)
    if fault is not None:
        raise SimulationError(f"reference failure ({fault})")
    return evaluate_candidate(task)


def faulty_calibration(work: Path, fmu: Path, *, pop_size: int, n_gen: int, workers: int, timeout: float) -> dict:
    import numpy as np

    from twin.calibration.problem import CalibrationTarget, ParameterSpace, calibrate
    from twin.executor import LocalExecutor
    from twin.fmu import FMU
    from twin.linearize import natural_frequencies
    truth = {"kt12": 1800.0, "c_mesh": 880.0}
    p = {**truth, "speed_ref_start": 2 * math.pi * 20, "load_start": 20.0}
    with FMU(fmu) as f:
        f.setup(0.0, parameters=p, inputs={"motor_speed_ref": 2 * math.pi * 20, "load_torque": 20.0})
        f.capture(0.1, 1e-5, ["accel_pinion_casing"])
        x = f.capture(0.3, 1e-5, ["accel_pinion_casing"])[:, 0]
    x = x + 0.05 * np.std(x) * np.random.default_rng(0).standard_normal(x.size)
    target = CalibrationTarget(x, 1e5, 20.0, 20.0, natural_frequencies(fmu, n=8, parameters=truth))
    space = ParameterSpace.from_bounds({"kt12": [1000.0, 2500.0], "c_mesh": [400.0, 1600.0]})
    runs = {}
    for label, fn in (("faulty", faulty_evaluate), ("reference", reference_evaluate)):
        t0 = time.monotonic()
        with LocalExecutor(workers, timeout=timeout) as ex:
            res = calibrate(fmu, space, target, algorithm="nsga2", pop_size=pop_size, n_gen=n_gen, seed=3,
                            executor=ex, settle=0.1, duration=0.2, evaluate=fn)
            crashes = list(ex._pool.crashes) if ex._pool is not None else []
        runs[label] = {"result": res, "wall": time.monotonic() - t0, "crashes": crashes}
    fa, ref = runs["faulty"]["result"], runs["reference"]["result"]
    kinds = [_fault_of(type("T", (), {"parameters": dict(zip(space.names, h["x"]))})()) for h in fa.history]
    same_history = len(fa.history) == len(ref.history) and all(
        a["x"] == b["x"] and ("failed" in a) == ("failed" in b) and a.get("f") == b.get("f")
        for a, b in zip(fa.history, ref.history))
    crash_msgs = [str(c) for c in runs["faulty"]["crashes"]]
    return {
        "evaluations": fa.n_evals,
        "segfaulting": kinds.count("segfault"), "hanging": kinds.count("hang"),
        "scored_infeasible": fa.failed_evals,
        "worker_deaths_reported": sum("SIGSEGV" in m for m in crash_msgs),
        "timeouts_reported": sum("time limit" in m for m in crash_msgs),
        "same_history": same_history,
        "same_front": bool(np.array_equal(fa.X, ref.X) and np.array_equal(fa.F, ref.F)),
        "same_pick": fa.chosen == ref.chosen,
        "chosen": fa.chosen,
        "wall_faulty_s": round(runs["faulty"]["wall"], 1), "wall_reference_s": round(runs["reference"]["wall"], 1),
        "pop_size": pop_size, "n_gen": n_gen, "workers": workers, "timeout_s": timeout,
    }


# ----------------------------------------------------------------------------------------------

def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", type=Path, help="work directory (default: a new temporary one, removed after)")
    ap.add_argument("--json", type=Path, help="write the tallies and every case here")
    ap.add_argument("--skip-calibration", action="store_true")
    ap.add_argument("--only", help="run only the cases whose name contains one of these ('|'-separated)")
    args = ap.parse_args(argv)
    work = args.work or Path(tempfile.mkdtemp(prefix="twin_robustness_"))
    if args.work is not None and work.exists() and any(work.iterdir()):
        ap.error(f"--work {work} is not empty: files of an earlier run would change the outcomes")
    work.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    tmp = Path(tempfile.gettempdir())
    temporaries = {p.name for pattern in ("twin_run_*", "twin_pool_*", "twin_fmu_*") for p in tmp.glob(pattern)}
    fmus = prepare(work)
    make_guards(work)
    only = args.only.split("|") if args.only else None
    all_cases = [c for c in cases(work, fmus) if not only or any(o in c.name for o in only)]
    rows = []
    tally = {c: 0 for c in CATEGORIES}
    try:
        for i, case in enumerate(all_cases, 1):
            cat, detail = run_case(case, work)
            tally[cat] += 1
            rows.append({"case": case.name, "kind": case.kind, "outcome": cat, "detail": detail})
            print(f"[{i:3d}/{len(all_cases)}] {cat:12s} {case.name}: {detail}", flush=True)
    finally:
        subprocess.run(["chattr", "-i", str(work / "ro")], capture_output=True)
    # temporary directories made during the cases and still there (a SIGKILLed parent's are removed
    # by the next run, which the cases after it are)
    leftovers = sorted({p.name for pattern in ("twin_run_*", "twin_pool_*", "twin_fmu_*") for p in tmp.glob(pattern)}
                       - temporaries)
    summary = {"date": time.strftime("%Y-%m-%d"), "machine": f"{platform.processor() or platform.machine()}, "
               f"{os.cpu_count()} CPUs", "cases": len(all_cases), "tally": tally,
               "kinds": {k: sum(1 for c in all_cases if c.kind == k) for k in sorted({c.kind for c in all_cases})},
               "temporary_dirs_left": leftovers, "wall_s": round(time.monotonic() - t0, 1), "rows": rows}
    print("\n" + ", ".join(f"{k}: {v}" for k, v in tally.items()) + f"  ({len(all_cases)} cases, "
          f"{summary['wall_s']} s)")
    if not args.skip_calibration:
        cal = faulty_calibration(work, fmus["gearbox"], pop_size=10, n_gen=4, workers=2, timeout=60.0)
        summary["faulty_calibration"] = cal
        print(json.dumps(cal, indent=1, default=str))
    if args.json:
        args.json.write_text(json.dumps(summary, indent=1, default=str))
    if args.work is None:
        shutil.rmtree(work, ignore_errors=True)
    bad = sum(v for k, v in tally.items() if k != "ok")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
