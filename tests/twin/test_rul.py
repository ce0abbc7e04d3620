"""twin.rul: RUL from assessed stages -- known answers, bands, determinism, bad inputs, I/O, CLI."""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from twin.errors import OutputPathError, TwinError
from twin.rul import (Observation, ObservationSet, RULError, RULEstimate, RULEstimator, Trajectory, add_subcommands,
                      read_json, read_observations, run_rul, simulate_assessments, write_json)

REPO = Path(__file__).resolve().parents[2]
STAGES = [0.0, 0.05, 0.10, 0.15, 0.20]


def linear() -> Trajectory:
    """D_model(N) = 1e-7 N: threshold 0.2 at 2e6 model cycles."""
    n = np.linspace(0.0, 4e6, 81)
    return Trajectory(n, 1e-7 * n, "pitting_density", "linear")


def power() -> Trajectory:
    """D_model(N) = 0.2 (N / 2e6)^1.5."""
    n = np.linspace(0.0, 4e6, 401)
    return Trajectory(n, 0.2 * (n / 2e6) ** 1.5, "pitting_density", "power")


def exact(traj: Trajectory, cycles, rate: float, stages=STAGES, conf: float = 1.0) -> ObservationSet:
    """One-hot (or ``conf``-peaked) observations of the true stage of D_model(rate N)."""
    b = np.asarray(stages)
    k_n = b.size - 1
    obs = []
    for i, n in enumerate(cycles):
        k = int(np.clip(np.searchsorted(b, traj.damage_at(rate * n), side="right") - 1, 0, k_n - 1))
        p = np.full(k_n, (1 - conf) / (k_n - 1))
        p[k] = conf
        obs.append(Observation(f"r{i:03d}", float(n), p))
    return ObservationSet(tuple(obs), tuple(stages))


# ---- known answers ---------------------------------------------------------------------------
def test_linear_trajectory_known_rul():
    # real gearbox twice as fast as the model: life 1e6 cycles; now = 6e5 -> RUL 4e5, D 0.12
    # (records placed so that none falls exactly on a stage boundary, which is ambiguous)
    obs = exact(linear(), np.linspace(1.3e4, 6e5, 35), rate=2.0)
    est = RULEstimator(linear(), STAGES, 0.2, offset_range=(0.0, 0.0)).fit(obs).estimate()
    assert est.now_cycles == 6e5
    assert est.rul_cycles == pytest.approx(4e5, rel=0.03)
    assert est.current_damage == pytest.approx(0.12, abs=0.004)
    assert est.rate_factor == pytest.approx(2.0, rel=0.02)
    assert est.failure_cycles == pytest.approx(1e6, rel=0.02)
    assert est.rul_band[0] <= 4e5 <= est.rul_band[1]
    assert est.damage_band[0] <= 0.12 <= est.damage_band[1]
    assert est.probability_failed == 0.0


def test_power_trajectory_with_unknown_offset():
    # rate 0.8 (slower than the model): real life 2.5e6; observe up to 2.1e6 (three stage
    # transitions seen, enough to pin down rate and offset) -> RUL 4e5
    obs = exact(power(), np.linspace(5e4, 2.1e6, 50), rate=0.8)
    est = RULEstimator(power(), STAGES, 0.2).fit(obs).estimate()
    assert est.rul_cycles == pytest.approx(4e5, rel=0.1)
    assert est.rul_band[0] <= 4e5 <= est.rul_band[1]
    assert est.current_damage == pytest.approx(0.2 * 0.84 ** 1.5, abs=0.005)
    # with only one transition seen the offset is not identifiable: the band is wide but holds
    early = RULEstimator(power(), STAGES, 0.2).fit(obs.head(25)).estimate()
    truth = 2.5e6 - early.now_cycles
    assert early.rul_band[0] <= truth <= early.rul_band[1]
    assert early.rul_band[1] - early.rul_band[0] > 3 * (est.rul_band[1] - est.rul_band[0])


def test_estimate_at_a_later_time_and_past_threshold():
    obs = exact(linear(), np.linspace(1.3e4, 6e5, 35), rate=2.0)
    fitted = RULEstimator(linear(), STAGES, 0.2, offset_range=(0.0, 0.0)).fit(obs)
    later = fitted.estimate(now=9e5)
    assert later.rul_cycles == pytest.approx(1e5, rel=0.15)
    past = fitted.estimate(now=1.5e6)
    assert past.rul_cycles == 0.0 and past.probability_failed > 0.95


def test_estimate_reads_the_stage_probabilities_not_only_the_argmax():
    # the same argmax sequence, but the last records lean towards the next stage -> earlier failure
    traj = linear()
    n = np.linspace(1.3e4, 6e5, 35)
    sure = exact(traj, n, rate=2.0, conf=0.9)
    leaning = []
    for o in sure.observations:
        p = o.probabilities.copy()
        k = int(np.argmax(p))
        if o.cycles > 4e5 and k + 1 < p.size:
            p[:] = 0.0
            p[k], p[k + 1] = 0.55, 0.45
        leaning.append(Observation(o.record, o.cycles, p))
    a = RULEstimator(traj, STAGES, 0.2, offset_range=(0, 0)).fit(sure).estimate()
    b = RULEstimator(traj, STAGES, 0.2, offset_range=(0, 0)).fit(ObservationSet(tuple(leaning))).estimate()
    assert b.rul_cycles < a.rul_cycles


def test_band_shrinks_with_more_observations():
    traj = power()
    sparse = exact(traj, np.linspace(1e5, 1.2e6, 4), rate=1.25, conf=0.9)
    dense = exact(traj, np.linspace(1e5, 1.2e6, 40), rate=1.25, conf=0.9)
    a = RULEstimator(traj, STAGES, 0.2).fit(sparse).estimate()
    b = RULEstimator(traj, STAGES, 0.2).fit(dense).estimate()
    assert a.now_cycles == b.now_cycles
    width = lambda e: e.rul_band[1] - e.rul_band[0]           # noqa: E731
    assert width(b) < 0.7 * width(a)


def test_band_shrinks_as_life_goes_on():
    traj = power()
    # life 2e6; the first stage boundary is passed at 40 % of life (D ~ N^1.5), so start after it
    obs = simulate_assessments(traj, STAGES, np.linspace(2e4, 1.9e6, 60), rate=1.0, seed=3)
    widths = []
    for m in (30, 45, 60):
        e = RULEstimator(traj, STAGES, 0.2).fit(obs.head(m)).estimate()
        widths.append(e.rul_band[1] - e.rul_band[0])
    assert widths[0] > widths[1] > widths[2]


# ---- determinism -----------------------------------------------------------------------------
def test_same_seed_same_output_and_other_seed_differs():
    traj = power()
    n = np.linspace(5e4, 1e6, 25)
    a = simulate_assessments(traj, STAGES, n, rate=1.3, seed=7)
    b = simulate_assessments(traj, STAGES, n, rate=1.3, seed=7)
    c = simulate_assessments(traj, STAGES, n, rate=1.3, seed=8)
    assert np.array_equal(a.probabilities, b.probabilities)
    assert not np.array_equal(a.probabilities, c.probabilities)
    ea = RULEstimator(traj, STAGES, 0.2).fit(a).estimate()
    eb = RULEstimator(traj, STAGES, 0.2).fit(b).estimate()
    assert ea == eb


def test_simulated_classifier_accuracy():
    traj = linear()
    n = np.linspace(1e4, 1e6, 400)
    obs = simulate_assessments(traj, STAGES, n, rate=2.0, accuracy=(0.9, 0.97), seed=0)
    truth = exact(traj, n, rate=2.0)
    hit = np.mean(np.argmax(obs.probabilities, 1) == np.argmax(truth.probabilities, 1))
    assert 0.88 <= hit <= 0.98
    assert np.allclose(obs.probabilities.sum(1), 1.0)


# ---- bad inputs: typed errors naming the value, nothing written -------------------------------
def _write(path: Path, records, **extra) -> Path:
    path.write_text(json.dumps({"records": records, **extra}))
    return path


def test_non_monotonic_cycles(tmp_path):
    f = _write(tmp_path / "a.json", [{"record": "a", "cycles": 2e5, "probabilities": [1, 0, 0, 0]},
                                     {"record": "b", "cycles": 1e5, "probabilities": [1, 0, 0, 0]}])
    with pytest.raises(RULError, match=r"record 'b'.*100000\.0 after 200000\.0"):
        read_observations(f, stages=STAGES)
    assert [o.record for o in read_observations(f, stages=STAGES, sort=True).observations] == ["b", "a"]
    one_hot = np.array([1.0, 0, 0, 0])
    obs = ObservationSet((Observation("x", 2.0, one_hot), Observation("y", 1.0, one_hot)))
    with pytest.raises(RULError, match="record 'y'"):
        RULEstimator(linear(), STAGES, 0.2).fit(obs)


def test_probabilities_not_summing_to_one(tmp_path):
    f = _write(tmp_path / "a.json", [{"record": "a", "cycles": 1e5, "probabilities": [0.5, 0.3, 0.1, 0.0]}])
    with pytest.raises(RULError, match=r"record 'a'.*sum to 0\.9"):
        read_observations(f, stages=STAGES)
    f = _write(tmp_path / "b.json", [{"record": "b", "cycles": 1e5, "probabilities": [1.2, -0.2, 0, 0]}])
    with pytest.raises(RULError, match=r"record 'b'.*>= 0.*-0\.2"):
        read_observations(f, stages=STAGES)


def test_wrong_number_of_stages(tmp_path):
    f = _write(tmp_path / "a.json", [{"record": "a", "cycles": 1e5, "probabilities": [0.5, 0.5, 0.0]}])
    with pytest.raises(RULError, match=r"record 'a'.*3 probabilities for 4 stages"):
        read_observations(f, stages=STAGES)
    obs = read_observations(f)                               # no stages known yet: accepted ...
    with pytest.raises(RULError, match="3 probabilities for 4 stages"):
        RULEstimator(linear(), STAGES, 0.2).fit(obs)         # ... but not by the estimator


@pytest.mark.parametrize("threshold", [5.0, 0.0, -0.1, float("nan")])
def test_threshold_outside_trajectory(threshold):
    with pytest.raises(RULError, match="threshold"):
        RULEstimator(linear(), STAGES, threshold)


@pytest.mark.parametrize("bad", [[0.0, 0.1], [0.0, 0.2, 0.1], [0.0, float("inf"), 1.0], "abc"])
def test_bad_stage_boundaries(bad):
    with pytest.raises(RULError, match="stage boundaries"):
        RULEstimator(linear(), bad, 0.2)


def test_bad_trajectory():
    with pytest.raises(RULError, match="non-decreasing"):
        Trajectory([0, 1, 2], [0, 0.2, 0.1], "pitting_density")
    with pytest.raises(RULError, match="increase strictly"):
        Trajectory([0, 2, 1], [0, 0.1, 0.2], "pitting_density")
    with pytest.raises(RULError, match="damage kind"):
        Trajectory([0, 1], [0, 0.1], "cracks")


def test_missing_cycles_and_time_without_speed(tmp_path):
    f = _write(tmp_path / "a.json", [{"record": "a", "probabilities": [1, 0, 0, 0]}])
    with pytest.raises(RULError, match="record 'a'.*no cycles"):
        read_observations(f, stages=STAGES)
    f = _write(tmp_path / "b.json", [{"record": "b", "time_s": 10.0, "probabilities": [1, 0, 0, 0]}])
    with pytest.raises(RULError, match="record 'b'.*speed_hz"):
        read_observations(f, stages=STAGES)
    assert read_observations(f, stages=STAGES, speed_hz=20.0).observations[0].cycles == 200.0
    with pytest.raises(RULError, match="does not exist"):
        read_observations(tmp_path / "nope.json")


def test_bad_output_paths_write_nothing(tmp_path):
    scen = _scenario(tmp_path)
    obs = _write(tmp_path / "obs.json", _records(), stages=STAGES)
    traj = linear()
    for kwargs in ({"json_path": tmp_path / "missing" / "o.json"}, {"plot_path": tmp_path / "o.pdf"},
                   {"json_path": tmp_path / "ok.json", "plot_path": tmp_path / "missing" / "p.png"},
                   {"json_path": tmp_path / "ok.txt"}):
        before = sorted(p.name for p in tmp_path.rglob("*"))
        with pytest.raises(OutputPathError):
            run_rul(scen, obs, trajectory=traj, **kwargs)
        assert sorted(p.name for p in tmp_path.rglob("*")) == before


# ---- I/O -------------------------------------------------------------------------------------
def _records():
    traj = linear()
    sim = simulate_assessments(traj, STAGES, np.linspace(5e4, 6e5, 12), rate=2.0, seed=1)
    return [{"record": o.record, "stage": int(np.argmax(o.probabilities)),
             "confidence": float(np.max(o.probabilities)), "probabilities": o.probabilities.tolist(),
             "cycles": o.cycles} for o in sim.observations]


def _scenario(tmp_path: Path):
    from twin.scenario import scenario_from_dict
    data = {"version": 1, "name": "t", "fmu": "GearTwin.Gearbox21", "stop_time": 1.0,
            "operating": {"speed": {"constant": 20}, "load": {"constant": 20}},
            "degradation": {"model": "pitting", "stop": {"pitting_density": 0.2}},
            "archive": {"stages": STAGES}}
    return scenario_from_dict(data, source=tmp_path / "t.yaml")


def test_json_round_trip(tmp_path):
    obs = exact(power(), np.linspace(5e4, 1e6, 20), rate=1.1, conf=0.9)
    fitted = RULEstimator(power(), STAGES, 0.2, speed_hz=20.0).fit(obs)
    est = fitted.estimate()
    out = write_json(tmp_path / "rul.json", est, fitted)
    assert read_json(out) == est
    assert RULEstimate.from_dict(json.loads(json.dumps(est.to_dict()))) == est
    doc = json.loads(out.read_text())
    assert doc["stages"] == STAGES and len(doc["records"]) == 20
    assert [p.name for p in tmp_path.iterdir()] == ["rul.json"]          # no temporary left behind
    with pytest.raises(RULError, match="not a gear-twin-rul"):
        read_json(_write(tmp_path / "x.json", []))


def test_assess_json_with_cycles_from_a_separate_file(tmp_path):
    recs = _records()
    cycles = {r["record"]: r.pop("cycles") for r in recs}
    assess = _write(tmp_path / "assess.json", recs)
    cfile = tmp_path / "cycles.csv"
    cfile.write_text("record,time_s\n" + "".join(f"{k},{v / 20.0}\n" for k, v in cycles.items()))
    obs = read_observations(assess, stages=STAGES, cycles_file=cfile, speed_hz=20.0)
    assert np.allclose(obs.cycles, list(cycles.values()))
    jfile = tmp_path / "cycles.json"
    jfile.write_text(json.dumps(cycles))
    assert np.allclose(read_observations(assess, cycles_file=jfile).cycles, list(cycles.values()))
    recs[0]["cycles"] = 1.0                                   # disagrees with the cycles file
    with pytest.raises(RULError, match=f"record '{recs[0]['record']}'.*disagree"):
        read_observations(_write(tmp_path / "bad.json", recs), cycles_file=jfile)


def test_csv_observations_and_stage_confidence_records(tmp_path):
    f = tmp_path / "obs.csv"
    f.write_text("record,time_s,p0,p1,p2,p3\na,10,0.9,0.1,0,0\nb,20,0.2,0.8,0,0\n")
    obs = read_observations(f, stages=STAGES, speed_hz=20.0)
    assert obs.cycles.tolist() == [200.0, 400.0]
    assert obs.probabilities[1].tolist() == [0.2, 0.8, 0.0, 0.0]
    g = _write(tmp_path / "s.json", [{"record": "a", "cycles": 5, "stage": 2, "confidence": 0.7}])
    p = read_observations(g, stages=STAGES).probabilities[0]
    assert p.tolist() == pytest.approx([0.1, 0.1, 0.7, 0.1])


# ---- CLI, plot, scenario trajectory ----------------------------------------------------------
def _degradation_h5(path: Path, traj: Trajectory) -> Path:
    import h5py
    with h5py.File(path, "w") as f:
        f.attrs["format"] = "gear-twin-degradation"
        f.attrs["model"] = "pitting"
        f.create_dataset("cycles", data=traj.cycles)
        f.create_dataset("damage", data=traj.damage)
    return path


def test_cli_handler(tmp_path, capsys):
    scen_file = tmp_path / "t.yaml"
    scen_file.write_text(
        "version: 1\nname: t\nfmu: GearTwin.Gearbox21\nstop_time: 1.0\n"
        "operating: {speed: {constant: 20}, load: {constant: 20}}\n"
        "degradation: {model: pitting, stop: {pitting_density: 0.2}}\n"
        f"archive: {{stages: {STAGES}}}\n")
    obs = _write(tmp_path / "assess.json", _records())
    h5 = _degradation_h5(tmp_path / "run.h5", linear())
    parser = argparse.ArgumentParser()
    sub = parser.add_subparsers(dest="command", required=True)
    add_subcommands(sub)
    args = parser.parse_args(["rul", str(scen_file), str(obs), "--trajectory", str(h5), "--json",
                              str(tmp_path / "o.json"), "--plot", str(tmp_path / "o.png"), "--no-progress"])
    assert args.handler(args) == 0
    out = capsys.readouterr().out
    assert "RUL [cycles]" in out and "RUL [h at 20 Hz]" in out and "current pitting density" in out
    est = read_json(tmp_path / "o.json")
    assert est.threshold == 0.2 and est.n_observations == 12
    assert est.rul_band[0] <= 1e6 - 6e5 <= est.rul_band[1]
    assert (tmp_path / "o.png").read_bytes()[:4] == b"\x89PNG"
    args = parser.parse_args(["rul", str(scen_file), str(obs), "--trajectory", str(h5), "--threshold", "0.9"])
    with pytest.raises(TwinError, match="threshold 0.9"):
        args.handler(args)


def test_help_does_not_import_numpy():
    code = ("import sys, argparse, twin.rul; p = argparse.ArgumentParser(); "
            "twin.rul.add_subcommands(p.add_subparsers()); sys.exit('numpy' in sys.modules)")
    assert subprocess.run([sys.executable, "-c", code], cwd=REPO).returncode == 0


def test_static_trajectory_of_the_lubricated_scenario():
    from twin.rul import trajectory_from_scenario
    from twin.scenario import load_scenario
    traj = trajectory_from_scenario(load_scenario(REPO / "scenarios" / "lubricated.yaml"), method="static")
    assert traj.kind == "pitting_density" and traj.max_damage > 0.25
    # README of twin.degradation: 20 % after 1.0e7 cycles with the healthy static load; the
    # load fed back (stiffness loss sheds load) makes it a little slower
    assert 1.0e7 <= traj.cycles_at(0.2) <= 1.15e7
