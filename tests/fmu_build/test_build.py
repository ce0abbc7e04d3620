"""fmu_build.build: what goes into an FMU, that nothing is per-model, caching, reproducibility.

Run-time behaviour of the generated FMUs (parameter changes, FMU state, output buffer) is in
test_wrapper.py; a plain C host is in test_c_host.py.
"""
from __future__ import annotations

import os
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest

import fmu_build
import fmu_build.build
from twin.errors import BuildError

REPO = Path(__file__).resolve().parents[2]
MODELICA = REPO / "modelica"
FMU_FIXTURES = ["gearbox_fmu", "two_mass_fmu"]


def _xml(fmu: Path) -> ET.Element:
    with zipfile.ZipFile(fmu) as zf:
        return ET.fromstring(zf.read("modelDescription.xml"))


def _real_variables(fmu: Path) -> list[ET.Element]:
    """ScalarVariable elements of type Real, in document order."""
    return [sv for sv in _xml(fmu).iter("ScalarVariable") if sv.find("Real") is not None]


# ---- contents of the two reference FMUs -------------------------------------------------------
@pytest.mark.needs_gcc
@pytest.mark.parametrize("fixture", FMU_FIXTURES)
def test_fmu_passes_fmpy_validation(fixture, request):
    from fmpy.validation import validate_fmu

    fmu = request.getfixturevalue(fixture)
    assert validate_fmu(str(fmu)) == []


@pytest.mark.needs_gcc
@pytest.mark.parametrize("fixture", FMU_FIXTURES)
def test_fmu_carries_c_sources_and_linux64_binary(fixture, request):
    fmu = request.getfixturevalue(fixture)
    root = _xml(fmu)
    identifier = root.get("modelName").replace(".", "_")
    with zipfile.ZipFile(fmu) as zf:
        names = set(zf.namelist())
        so = zf.read(f"binaries/linux64/{identifier}.so")
    assert so[:4] == b"\x7fELF"
    c_files = sorted(n for n in names if n.startswith("sources/") and n.endswith(".c"))
    assert c_files == ["sources/fmi2_wrapper.c", "sources/model_functions.c"]
    # Everything a rebuild from sources/ needs (test_c_host.py actually compiles it).
    for header in ("model_info.h", "fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"):
        assert f"sources/{header}" in names
    for interface in ("ModelExchange", "CoSimulation"):
        element = root.find(interface)
        assert element is not None and element.get("modelIdentifier") == identifier
        listed = sorted(f"sources/{f.get('name')}" for f in element.find("SourceFiles").findall("File"))
        assert listed == c_files


@pytest.mark.needs_gcc
@pytest.mark.parametrize("fixture", FMU_FIXTURES)
def test_parameters_are_tunable_with_start_values(fixture, request):
    variables = _real_variables(request.getfixturevalue(fixture))
    params = [sv for sv in variables if sv.get("causality") == "parameter"]
    calculated = [sv for sv in variables if sv.get("causality") == "calculatedParameter"]
    assert len(params) >= 5
    for sv in params:
        assert (sv.get("variability"), sv.get("initial")) == ("tunable", "exact"), sv.get("name")
        assert sv.find("Real").get("start") is not None, sv.get("name")
    for sv in calculated:
        assert (sv.get("variability"), sv.get("initial")) == ("tunable", "calculated"), sv.get("name")
    solver = {sv.get("name"): float(sv.find("Real").get("start")) for sv in params
              if sv.get("name").startswith("solver.")}
    assert solver == {"solver.step_size": fmu_build.DEFAULT_STEP_SIZE, "solver.output_interval": 0.0}


@pytest.mark.needs_gcc
@pytest.mark.parametrize("fixture", FMU_FIXTURES)
def test_value_references_follow_the_documented_layout(fixture, request):
    """Real value references are 0..n-1 in the order p, q, u, y, x, der(x), solver.* (README)."""
    variables = _real_variables(request.getfixturevalue(fixture))

    def group(sv) -> int:
        name, causality = sv.get("name"), sv.get("causality")
        if name == "solver.step_size":
            return 6
        if name == "solver.output_interval":
            return 7
        if causality == "local":
            return 5 if sv.find("Real").get("derivative") else 4
        return {"parameter": 0, "calculatedParameter": 1, "input": 2, "output": 3}[causality]

    assert [int(sv.get("valueReference")) for sv in variables] == list(range(len(variables)))
    groups = [group(sv) for sv in variables]
    assert groups == sorted(groups)
    assert groups[-2:] == [6, 7]
    # every state has exactly one derivative, in the same order
    n_states, n_ders = groups.count(4), groups.count(5)
    assert n_states == n_ders > 0


# ---- a different .mo gives a different FMU ------------------------------------------------------
# (causality, variability, unit, start, description), transcribed from TwoMassOscillator.mo.
TWO_MASS_VARIABLES = {
    "m1": ("parameter", "tunable", "kg", 1.0, "Mass 1"),
    "m2": ("parameter", "tunable", "kg", 0.5, "Mass 2"),
    "k1": ("parameter", "tunable", "N/m", 100.0, "Ground spring of mass 1"),
    "k12": ("parameter", "tunable", "N/m", 50.0, "Coupling spring"),
    "d1": ("parameter", "tunable", "N.s/m", 0.2, "Ground damper of mass 1"),
    "f1": ("calculatedParameter", "tunable", "Hz", None, "Natural frequency of mass 1 alone"),
    "force": ("input", "continuous", "N", 0.0, "Force on mass 2"),
    "a2": ("output", "continuous", "m/s2", None, "Acceleration of mass 2"),
    "position2": ("output", "continuous", "m", None, "Position of mass 2"),
    "x1": ("local", "continuous", "m", None, "Position of mass 1"),
    "v1": ("local", "continuous", "m/s", None, "Velocity of mass 1"),
    "x2": ("local", "continuous", "m", None, "Position of mass 2"),
    "v2": ("local", "continuous", "m/s", None, "Velocity of mass 2"),
    "der(x1)": ("local", "continuous", "m/s", None, "Time derivative of x1"),
    "der(v1)": ("local", "continuous", "m/s2", None, "Time derivative of v1"),
    "der(x2)": ("local", "continuous", "m/s", None, "Time derivative of x2"),
    "der(v2)": ("local", "continuous", "m/s2", None, "Time derivative of v2"),
    "solver.step_size": ("parameter", "tunable", "s", fmu_build.DEFAULT_STEP_SIZE,
                         "Largest internal Runge-Kutta 4 step of the co-simulation"),
    "solver.output_interval": ("parameter", "tunable", "s", 0.0,
                               "Interval of the outputs buffered inside each doStep (0 = off)"),
}


@pytest.mark.needs_gcc
def test_two_mass_variables_are_those_of_its_mo_file(two_mass_fmu, gearbox_fmu):
    found = {}
    for sv in _real_variables(two_mass_fmu):
        real = sv.find("Real")
        start = real.get("start")
        found[sv.get("name")] = (sv.get("causality"), sv.get("variability"), real.get("unit"),
                                 None if start is None else float(start), sv.get("description"))
    assert found == TWO_MASS_VARIABLES
    # the algebraic spring_force is eliminated, not exported
    assert "spring_force" in (MODELICA / "GearTwin/Examples/TwoMassOscillator.mo").read_text()
    two, gear = _xml(two_mass_fmu), _xml(gearbox_fmu)
    assert two.get("guid") != gear.get("guid")
    assert two.find("CoSimulation").get("modelIdentifier") == "GearTwin_Examples_TwoMassOscillator"
    assert two.get("description") == "Two masses on springs, one driven by an input force"
    gear_names = {sv.get("name") for sv in _real_variables(gearbox_fmu)}
    assert gear_names & set(found) == {"solver.step_size", "solver.output_interval"}


@pytest.mark.needs_gcc
def test_two_mass_response_matches_matrix_exponential(two_mass_fmu, open_slave, two_mass):
    """RK4 at solver.step_size = 1e-4 s vs expm of the 4-state linear ODE, forced by 0.5 N."""
    force, h, n = 0.5, 1e-3, 1000
    slave, vr = open_slave(two_mass_fmu, step_size=1e-4, force=force)
    names = ["x1", "v1", "x2", "v2", "a2", "position2"]
    rows = []
    for k in range(n):
        slave.doStep(k * h, h)
        rows.append(slave.getReal([vr[v] for v in names]))
    sim = np.array(rows)
    times = h * np.arange(1, n + 1)
    exact = two_mass.solution(times, [*two_mass.x0, force])
    p = two_mass.defaults
    a2 = (force - p["k12"] * (exact[:, 2] - exact[:, 0])) / p["m2"]
    reference = np.column_stack([exact[:, :4], a2, exact[:, 2]])
    # error relative to each signal's amplitude (the signals cross zero)
    rel = np.abs(sim - reference).max(axis=0) / np.abs(reference).max(axis=0)
    assert rel.max() < 1e-6, dict(zip(names, rel))


# ---- a model written at test time, in its own package --------------------------------------------
LAB = """
  model Cascade "Three first-order lags in series driven by an input"
    parameter Integer n = 3 "Number of lags (structural)";
    parameter Real tau[n](each unit = "s") = {0.1, 0.2, 0.4} "Time constants";
    parameter Real gain = 2.0 "Input gain";
    parameter Real rate[n](each unit = "1/s") = {1 / tau[i] for i in 1:n} "Inverse time constants";
    input Real u(unit = "V", start = 1.0) "Drive";
    Real x[n](each start = 0.0, each fixed = true) "Lag outputs";
    output Real y(unit = "V") "Last lag output";
    output Real excess(unit = "V") = noEvent(if x[1] > 0.5 then x[1] - 0.5 else 0.0) "First lag above 0.5 V";
  equation
    der(x[1]) = rate[1] * (gain * u - x[1]);
    der(x[2]) = rate[2] * (x[1] - x[2]);
    der(x[3]) = rate[3] * (x[2] - x[3]);
    y = x[n];
  end Cascade;
"""


def _cascade_exact(times, tau, gain, u):
    """(len(times), 3) exact lag outputs from x(0) = 0 with a constant input, via expm."""
    from scipy.linalg import expm

    r = 1.0 / np.asarray(tau)
    a = np.array([[-r[0], 0, 0, r[0] * gain * u],
                  [r[1], -r[1], 0, 0],
                  [0, r[2], -r[2], 0],
                  [0, 0, 0, 0]])
    return np.array([(expm(a * t) @ [0, 0, 0, 1.0])[:3] for t in times])


@pytest.mark.needs_gcc
def test_model_written_at_test_time_builds_and_simulates(tmp_path, write_package, open_slave):
    write_package(tmp_path / "lib", "Lab", LAB)
    fmu = fmu_build.build_fmu("Lab.Cascade", tmp_path / "lib", tmp_path / "out")
    assert fmu == tmp_path / "out" / "Lab.Cascade.fmu"
    from fmpy.validation import validate_fmu
    assert validate_fmu(str(fmu)) == []

    kinds = {sv.get("name"): sv.get("causality") for sv in _real_variables(fmu)}
    assert kinds == {
        "tau[1]": "parameter", "tau[2]": "parameter", "tau[3]": "parameter", "gain": "parameter",
        "rate[1]": "calculatedParameter", "rate[2]": "calculatedParameter", "rate[3]": "calculatedParameter",
        "u": "input", "y": "output", "excess": "output",
        "x[1]": "local", "x[2]": "local", "x[3]": "local",
        "der(x[1])": "local", "der(x[2])": "local", "der(x[3])": "local",
        "solver.step_size": "parameter", "solver.output_interval": "parameter",
    }
    integers = {sv.get("name"): sv.find("Integer").get("start") for sv in _xml(fmu).iter("ScalarVariable")
                if sv.find("Integer") is not None}
    assert integers == {"n": "3"}

    # tau[3] changed before initialisation: the calculated rate[3] follows it.
    tau, gain, u, h = (0.1, 0.2, 0.25), 2.0, 0.7, 1e-2
    slave, vr = open_slave(fmu, step_size=1e-4, u=u, **{"tau[3]": tau[2]})
    assert slave.getReal([vr["rate[3]"]]) == pytest.approx([4.0], rel=1e-15)
    rows = []
    for k in range(100):
        slave.doStep(k * h, h)
        rows.append(slave.getReal([vr["x[1]"], vr["x[2]"], vr["x[3]"], vr["y"], vr["excess"]]))
    sim = np.array(rows)
    exact = _cascade_exact(h * np.arange(1, 101), tau, gain, u)
    assert np.abs(sim[:, :3] - exact).max() < 1e-9 * np.abs(exact).max()
    assert np.array_equal(sim[:, 3], sim[:, 2])
    assert np.allclose(sim[:, 4], np.maximum(sim[:, 0] - 0.5, 0.0), rtol=0, atol=1e-15)
    assert sim[-1, 4] > 0.5      # the noEvent branch was taken


# ---- caching and reproducibility ---------------------------------------------------------------
@pytest.mark.needs_gcc
def test_cache_skips_rebuild_until_the_source_changes(tmp_path, write_package, monkeypatch):
    mo = write_package(tmp_path / "lib", "Lab", LAB)
    out = tmp_path / "out"
    t0 = time.perf_counter()
    fmu = fmu_build.build_fmu("Lab.Cascade", tmp_path / "lib", out)
    first_build = time.perf_counter() - t0
    stamp = out / ".Lab.Cascade.fmu.hash"
    assert stamp.exists()
    mtime, guid, key = fmu.stat().st_mtime_ns, _xml(fmu).get("guid"), stamp.read_text()

    # A cached build must neither flatten nor call gcc: make both fail loudly if reached.
    def forbidden(*args, **kwargs):
        raise AssertionError("cached build recompiled")
    with monkeypatch.context() as m:
        m.setattr(fmu_build.build, "flatten", forbidden)
        m.setattr(fmu_build.build.subprocess, "run", forbidden)
        t0 = time.perf_counter()
        again = fmu_build.build_fmu("Lab.Cascade", tmp_path / "lib", out)
        cached = time.perf_counter() - t0
        # the key is the content, not the file time
        os.utime(mo, ns=(mo.stat().st_atime_ns, mo.stat().st_mtime_ns + 10**9))
        assert fmu_build.build_fmu("Lab.Cascade", tmp_path / "lib", out) == fmu
    assert again == fmu and fmu.stat().st_mtime_ns == mtime
    assert cached < min(0.5, first_build), (cached, first_build)

    # Editing the model (a new default value) rebuilds, with a new GUID and the new default.
    mo.write_text(mo.read_text().replace("parameter Real gain = 2.0", "parameter Real gain = 3.0"))
    rebuilt = fmu_build.build_fmu("Lab.Cascade", tmp_path / "lib", out)
    assert rebuilt == fmu and fmu.stat().st_mtime_ns != mtime
    root = _xml(fmu)
    assert root.get("guid") != guid
    gain = next(sv for sv in root.iter("ScalarVariable") if sv.get("name") == "gain")
    assert float(gain.find("Real").get("start")) == 3.0
    assert stamp.read_text() != key

    # The build options are part of the key too.
    mtime = fmu.stat().st_mtime_ns
    fmu_build.build_fmu("Lab.Cascade", tmp_path / "lib", out, step_size=1e-5)
    assert fmu.stat().st_mtime_ns != mtime
    step = next(sv for sv in _xml(fmu).iter("ScalarVariable") if sv.get("name") == "solver.step_size")
    assert step.find("Real").get("start") == "1e-05"


@pytest.mark.needs_gcc
def test_forced_builds_into_different_directories_are_byte_identical(tmp_path, monkeypatch):
    """With SOURCE_DATE_EPOCH set (reproducible-builds.org), generationDateAndTime is that date
    and two builds are byte-identical; without it, it is the time of the build."""
    model = "GearTwin.Examples.TwoMassOscillator"
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1764028800")
    a = fmu_build.build_fmu(model, MODELICA, tmp_path / "a", force=True)
    time.sleep(1.1)
    b = fmu_build.build_fmu(model, MODELICA, tmp_path / "b", force=True)
    assert a.read_bytes() == b.read_bytes()
    assert _xml(a).get("generationDateAndTime") == "2025-11-25T00:00:00Z"
    monkeypatch.delenv("SOURCE_DATE_EPOCH")
    before = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(time.time() - 1))
    c = fmu_build.build_fmu(model, MODELICA, tmp_path / "c", force=True)
    assert before <= _xml(c).get("generationDateAndTime") <= time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
    with zipfile.ZipFile(a) as zf:
        infos = zf.infolist()
    assert [i.filename for i in infos] == sorted(i.filename for i in infos)
    assert {i.date_time for i in infos} == {(2000, 1, 1, 0, 0, 0)}


# ---- errors ------------------------------------------------------------------------------------
def test_unknown_model_is_named(tmp_path, write_package):
    write_package(tmp_path / "lib", "Lab", LAB)
    with pytest.raises(BuildError, match=r"Nowhere\.Cascade.*not found"):
        fmu_build.build_fmu("Nowhere.Cascade", tmp_path / "lib", tmp_path / "out")
    with pytest.raises(BuildError, match=r"Lab\.Missing"):
        fmu_build.build_fmu("Lab.Missing", tmp_path / "lib", tmp_path / "out")
    assert not (tmp_path / "out" / "Lab.Missing.fmu").exists()


def test_missing_modelica_directory_is_named(tmp_path):
    missing = tmp_path / "no_such_dir"
    with pytest.raises(BuildError, match=f"Modelica directory {missing} does not exist"):
        fmu_build.build_fmu("Lab.Cascade", missing, tmp_path / "out")


def test_non_positive_step_size_is_refused(tmp_path, write_package):
    write_package(tmp_path / "lib", "Lab", LAB)
    for bad in (0.0, -1e-6, float("nan")):
        with pytest.raises(BuildError, match="step_size must be > 0"):
            fmu_build.build_fmu("Lab.Cascade", tmp_path / "lib", tmp_path / "out", step_size=bad)


@pytest.mark.needs_gcc
def test_python_dash_m_entry_point(tmp_path, write_package):
    write_package(tmp_path / "lib", "Lab", LAB)
    cmd = [sys.executable, "-m", "fmu_build", "--modelica-dir", str(tmp_path / "lib"), "--out", str(tmp_path / "o")]
    ok = subprocess.run([*cmd, "Lab.Cascade"], cwd=REPO, capture_output=True, text=True)
    assert ok.returncode == 0, ok.stderr
    assert ok.stdout.strip() == str(tmp_path / "o" / "Lab.Cascade.fmu")
    bad = subprocess.run([*cmd, "Lab.Missing"], cwd=REPO, capture_output=True, text=True)
    assert bad.returncode == 2
    assert bad.stderr.startswith("fmu_build: error:") and "Lab.Missing" in bad.stderr


def test_builder_needs_no_per_model_code():
    """The builder and wrapper mention no model of this repository."""
    sources = [*sorted((REPO / "fmu_build").glob("*.py")), *sorted((REPO / "fmu_build/templates").glob("*.[ch]"))]
    for path in sources:
        text = path.read_text()
        for word in ("TwoMass", "mesh_force", "theta5"):
            assert word not in text, (path.name, word)


HOOKED = """
model Base
  parameter Real k = 4.0;
  parameter Real p[2] = {1, 2};
  Real x(start = 1.0);
  Real v(start = 0.0);
  Real hook = 0 "zero here; a variant binds it";
  output Real y;
equation
  der(x) = v;
  der(v) = -k * x + hook + p[1];
  y = x + p[2];
end Base;
block Ripple
  parameter Real amplitude = 1.0;
  parameter Real shape[2] = {amplitude, 0.5};
  input Real angle;
  output Real force;
  Real z(start = 0);
equation
  der(z) = -z + angle;
  force = amplitude * sin(angle) + z;
end Ripple;
model Variant
  extends Base(hook = ripple.force, p = ripple.shape);
  Ripple ripple(angle = 2 * x, amplitude = 0.5);
end Variant;
"""


@pytest.mark.needs_gcc
def test_extends_with_a_component_bound_to_hooks_and_parameters(tmp_path, write_package):
    """A base parameter bound to a component parameter declared after it, and a component input
    bound to a base state, build into one ODE; the component's input and output stay internal."""
    from scipy.integrate import solve_ivp

    from twin.fmu import FMU
    write_package(tmp_path / "lib", "Hooked", HOOKED)
    fmu = fmu_build.build_fmu("Hooked.Variant", tmp_path / "lib", tmp_path / "out")
    kinds = {sv.get("name"): sv.get("causality") for sv in _real_variables(fmu)}
    assert kinds["ripple.amplitude"] == "parameter"
    assert kinds["p[1]"] == "calculatedParameter" and kinds["ripple.shape[1]"] == "calculatedParameter"
    assert kinds["y"] == "output" and kinds.get("ripple.force") != "output"
    assert "ripple.angle" not in kinds or kinds["ripple.angle"] != "input"

    amp = 0.7

    def rhs(t, s):
        x, v, z = s
        angle = 2 * x
        return [v, -4.0 * x + amp * np.sin(angle) + z + amp, -z + angle]

    ref = solve_ivp(rhs, (0, 1.0), [1.0, 0.0, 0.0], t_eval=np.linspace(0.1, 1.0, 10), rtol=1e-10, atol=1e-12)
    with FMU(fmu) as f:
        f.setup(0.0, parameters={"ripple.amplitude": amp})
        y = f.capture(1.0, 0.1, ["y"])[:, 0]
    np.testing.assert_allclose(y, ref.y[0] + 0.5, rtol=0, atol=1e-8)
