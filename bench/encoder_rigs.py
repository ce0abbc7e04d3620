"""Benchmark: what a shaft encoder sees of the rigs' hidden effects, against the casing accelerometer.

    python bench/encoder_rigs.py [--rigs pedestal beam] [--seeds 1 2 3 4 5] [--out bench_out/encoder_rigs]

The diagnosis reads one casing accelerometer; the rigs (rigs/pedestal, rigs/beam) also record the
pinion shaft's angle with an encoder at its free end, as real test rigs do. Below the first
torsional mode a run-out or a drive-torque ripple turns the gears rather than shaking the casing,
so what it changes may show in the shaft's angle and not in the casing.

Per rig and gearbox ``Rig().scattered(seed, 0.12)``: three healthy 2 s steady records (20 Hz,
20 N.m; the diagnosis benchmark's ``none`` case seed and two more) and one with each hidden effect
(the rig's own implementation and default size, the diagnosis benchmark's case seeds). For each
record, at the signature frequency of the effect (the pinion's speed for a pinion run-out, the
gear's for a gear run-out, the ripple's frequency from the truth file for a drive ripple; read at
the record's own speed from its encoder):

* encoder: the amplitude of the angular vibration (the encoder angle less a quadratic in time,
  Hann window, largest bin within +-2 bins) [rad];
* casing: the level of the pinion casing accelerometer's first sidebands around the first six
  mesh harmonics at that shaft's speed (mean of the twelve, dB) for a run-out; the level of the
  line itself for a ripple.

Scored: the change [dB] against the healthy records' mean, and the margin: the change less the
largest deviation of a healthy record from that mean. An effect counts as **seen** by a channel when
its margin is at least 6 dB (the compare's line threshold, fixed before the run). Written apart from
``twin`` (numpy only): the twin's code is not used. Prints a Markdown table; writes results.json.
"""
from __future__ import annotations

import argparse
import importlib
import json
import os
import platform
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

SPEED, LOAD = 20.0, 20.0
Z1, Z2 = 19, 52
SEEN_DB = 6.0
#: the diagnosis benchmark's case seeds (100 + the case's index among its sorted case names)
CASE_SEEDS = {"bearing_outer_race": 100, "casing_resonance": 101, "coupling_misalignment": 102,
              "drive_ripple": 103, "gear_runout": 104, "local_tooth_fault": 105, "none": 106,
              "pinion_runout": 107}
HEALTHY_SEEDS = (106, 201, 202)
CASES = ("pinion_runout", "gear_runout", "drive_ripple")


def angular_vibration(angle: np.ndarray, fs: float) -> tuple[np.ndarray, float]:
    """(angle less a quadratic in time [rad], mean speed [Hz])."""
    t = np.arange(angle.size) / fs
    p = np.polyfit(t, angle, 2)
    speed = float(np.polyval(np.polyder(p), t).mean() / (2 * np.pi))
    return angle - np.polyval(p, t), speed


def line_amplitude(x: np.ndarray, fs: float, f0: float, bins: int = 2) -> float:
    """Amplitude of the line nearest f0 (Hann window, largest bin within +-bins)."""
    w = np.hanning(x.size)
    spec = 2.0 * np.abs(np.fft.rfft(w * (x - x.mean()))) / w.sum()
    i = int(round(f0 * x.size / fs))
    return float(spec[max(i - bins, 0): i + bins + 1].max())


def features(rec, ripple_hz: float) -> dict:
    fs = float(rec.sample_rate)
    av, shaft = angular_vibration(np.asarray(rec.channels["encoder"], float), fs)
    acc = np.asarray(rec.channels["accel_pinion_casing"], float)
    gear = shaft * Z1 / Z2
    gmf = Z1 * shaft

    def sidebands(fo: float) -> float:
        amps = [line_amplitude(acc, fs, k * gmf + s * fo) for k in range(1, 7) for s in (-1, 1)]
        return float(20 * np.log10(np.mean(amps)))

    return {"encoder": {"pinion_runout": line_amplitude(av, fs, shaft), "gear_runout": line_amplitude(av, fs, gear),
                        "drive_ripple": line_amplitude(av, fs, ripple_hz)},
            "casing_db": {"pinion_runout": sidebands(shaft), "gear_runout": sidebands(gear),
                          "drive_ripple": float(20 * np.log10(line_amplitude(acc, fs, ripple_hz)))},
            "shaft_hz": shaft}


def score(rig_name: str, seed: int) -> list[dict]:
    rigmod = importlib.import_module(f"rigs.{rig_name}")
    box = rigmod.Rig().scattered(seed=seed, scatter=0.12)
    recs = {}
    for name in CASES:
        recs[name] = box.steady(speed=SPEED, load=LOAD, duration=2.0, effect=name, seed=CASE_SEEDS[name],
                                name="steady")
    ripple = recs["drive_ripple"].truth["effect"]
    ripple_hz = float(ripple.get("params", ripple)["frequency"])      # the beam rig nests them
    healthy = [features(box.steady(speed=SPEED, load=LOAD, duration=2.0, effect=None, seed=s, name="steady"),
                        ripple_hz) for s in HEALTHY_SEEDS]
    rows = []
    for name in CASES:
        f = features(recs[name], ripple_hz)
        row = {"rig": rig_name, "seed": seed, "case": name,
               "truth": recs[name].truth["effect"]}
        for ch in ("encoder", "casing"):
            if ch == "encoder":
                h = np.array([20 * np.log10(x["encoder"][name]) for x in healthy])
                v = 20 * np.log10(f["encoder"][name])
            else:
                h = np.array([x["casing_db"][name] for x in healthy])
                v = f["casing_db"][name]
            change = float(v - h.mean())
            margin = change - float(np.max(np.abs(h - h.mean())))
            row[ch] = {"change_db": change, "margin_db": margin, "seen": bool(margin >= SEEN_DB)}
        row["encoder"]["amplitude_rad"] = f["encoder"][name]
        row["encoder"]["healthy_rad"] = [x["encoder"][name] for x in healthy]
        rows.append(row)
    return rows


def table(rows: list[dict]) -> str:
    out = ["| rig | hidden | encoder: change [dB] (gearboxes seen) | casing: change [dB] (gearboxes seen) |",
           "|---|---|---|---|"]
    for rig in dict.fromkeys(r["rig"] for r in rows):
        for case in CASES:
            sel = [r for r in rows if r["rig"] == rig and r["case"] == case]
            cells = []
            for ch in ("encoder", "casing"):
                ch_ = [r[ch]["change_db"] for r in sel]
                cells.append(f"{np.median(ch_):+.1f} ({min(ch_):+.1f} to {max(ch_):+.1f}); "
                             f"{sum(r[ch]['seen'] for r in sel)} of {len(sel)}")
            out.append(f"| {rig} | {case} | {cells[0]} | {cells[1]} |")
    return "\n".join(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rigs", nargs="+", default=["pedestal", "beam"])
    ap.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3, 4, 5])
    ap.add_argument("--out", type=Path, default=REPO / "bench_out" / "encoder_rigs")
    a = ap.parse_args()
    a.out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    rows = []
    for rig in a.rigs:
        for seed in a.seeds:
            rows += score(rig, seed)
            print(f"{rig} seed {seed}: {time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)
    (a.out / "results.json").write_text(json.dumps(rows, indent=1))
    print(f"Machine: {platform.machine()}, {os.cpu_count()} cores, {time.strftime('%Y-%m-%d %H:%M')}; "
          f"{time.perf_counter() - t0:.0f} s; seen: margin >= {SEEN_DB:.0f} dB over the healthy records' spread\n")
    print(table(rows))


if __name__ == "__main__":
    main()
