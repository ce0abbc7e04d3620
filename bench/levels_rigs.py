"""The level fit of `twin calibrate` judged again on gearboxes `bench/calibration_rigs.py` calibrated.

    python bench/levels_rigs.py OUT [OUT ...]

The level fit (sensor gain, roughness and process-force levels, :mod:`twin.calibration.levels`)
comes after the modes are fitted and moves no mode. So a change to it can be judged on the modes
a finished run fitted: for each gearbox in OUT/results.json its calibrated parameters are taken
without their levels (the gain, roughness and process RMS removed, each casing panel's
participation put back to the 1 / (sensors sharing the panels) the sensor path starts from), the levels are fitted by the
current code as `twin calibrate` does (fit, panel participations, fit again) to the gearbox's
steady record, and the twin is simulated (2 s at the record's speed and load). Printed per gearbox
and as a mean per rig: the spectral distance of ``bench/spectral_distance.py`` (floor-aware,
gain-free, not ``twin.compare``) of the calibrated twin in OUT (the code that wrote it) and with
the levels fitted now, and the level fit's warning when the mesh lines ask for a sensor gain
outside its declared range.
"""
from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))

CHANNEL = "accel_pinion_casing"
LEVEL_KEYS = re.compile(r"^(sensor_pinion\.gain|pinion_roughness\.rms|gear_roughness\.rms|process\.rms)$")
PARTICIPATION = re.compile(r"^(sensor_\w+)\.panel_participation\[\d\]$")


def without_levels(parameters: dict) -> dict:
    """The calibrated parameters as the level fit found them: no levels; each panel's participation
    1 / the number of sensors given panels (``twin.calibration.sensor_path.casing_path``'s start)."""
    out = {k: v for k, v in parameters.items() if not LEVEL_KEYS.match(k)}
    sensors = {PARTICIPATION.match(k).group(1) for k, v in out.items() if PARTICIPATION.match(k) and v}
    return {k: (1.0 / len(sensors) if PARTICIPATION.match(k) and v else v) for k, v in out.items()}


def refit(out: Path, gearbox: dict) -> dict:
    from spectral_distance import spectral_distance_report

    from twin.calibration.levels import fit_levels_and_panels
    from twin.measurements import load_measurements
    from twin.operating import simulate_operating_point
    from twin.scenario import load_scenario

    rig, seed = gearbox["rig"], gearbox["seed"]
    h5 = sorted(out.glob(f"{rig}_{seed}*.h5"))[0]
    calibrated = load_scenario(out / f"{rig}_{seed}_cal" / "calibrated.yaml")
    fmu = calibrated.fmu_path()
    rec = load_measurements(h5)["steady"]
    fs = float(rec.sample_rate)
    x = np.asarray(rec[CHANNEL], float)
    kw = dict(speed_hz=float(rec.nominal_speed), load_nm=float(rec.load), channel=CHANNEL, fmin=20.0,
              fmax=min(5000.0, 0.45 * fs), settle=0.2)
    params = without_levels(dict(calibrated.parameters))
    levels, updates = fit_levels_and_panels(fmu, params, x, fs, **kw)
    params.update(updates)
    y = simulate_operating_point(fmu, float(rec.nominal_speed), float(rec.load), parameters=params, settle=0.2,
                                 duration=min(x.size / fs, 2.0), channels=[CHANNEL], output_interval=1.0 / fs)[:, 0]
    now = spectral_distance_report(y, x[-y.size:], fs, fmin=20.0, fmax=5000.0)
    return {"rig": rig, "seed": seed, "before_db": gearbox["spectrum"]["calibrated twin"]["distance_db"],
            "now_db": now["distance_db"], "levels": levels.describe(), "warning": levels.warning()}


def main(argv=None) -> int:
    from mode_losses import read_run

    dirs = [Path(a) for a in (sys.argv[1:] if argv is None else argv)]
    if not dirs:
        print(__doc__)
        return 2
    for out in dirs:
        gearboxes = read_run(out)
        if gearboxes is None:
            return 2
        rows = []
        for g in gearboxes:
            r = refit(out, g)
            rows.append(r)
            print(f"{r['rig']} {r['seed']}: {r['before_db']:.1f} -> {r['now_db']:.1f} dB; {r['levels']}"
                  + (f"; warning: {r['warning']}" if r["warning"] else ""), flush=True)
        before, now = np.mean([r["before_db"] for r in rows]), np.mean([r["now_db"] for r in rows])
        print(f"| {out.name} | {before:.1f} -> {now:.1f} dB | worst change {max(r['now_db'] - r['before_db'] for r in rows):+.1f} dB "
              f"| gain held at a bound {sum(bool(r['warning']) for r in rows)}/{len(rows)} |")
        (out / "levels_now.json").write_text(json.dumps(rows, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
