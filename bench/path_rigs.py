"""The shape of the path from a struck point to the casing sensor: a rig's hammer records against the twin.

    python bench/path_rigs.py OUT [OUT ...]

For each gearbox `bench/calibration_rigs.py --hammer` calibrated in OUT, and each of its hammer
records: the measured FRF from the hammer's force to the pinion casing channel (H1, 8 Hz bins,
numpy/scipy only), and the calibrated twin's FRF from a force on the body that stands for the
struck point (:data:`STRUCK_BODY`, vertical; the linearisation at the hammer test's slow roll, the
broadband sources off). Each as its mean level in octave bands re its own 800-1600 Hz band, so a
gain or a wrong struck body's level drops out and the *shape* of the path is compared: how much
the path passes at low against high frequencies. Printed per record and as a mean per rig.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy import signal as sps

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "bench"))

CHANNEL = "accel_pinion_casing"
#: The twin's body (velocity state, mass parameter) for each rig's struck point: the pedestal rig's
#: pinion and gear supports as the pedestals beside the sensors (6 and 9), the beam rig's shaft ends
#: as the gears on their shafts (the base models carry no shaft ends).
STRUCK_BODY = {"pedestal": {"hammer_pinion_pedestal": ("vy6", "m6"), "hammer_gear_pedestal": ("vy9", "m9")},
               "beam": {"hammer_pinion_shaft_end": ("vy5", "m5"), "hammer_gear_shaft_end": ("vy10", "m10")}}
BANDS = (100, 200, 400, 800, 1600, 3200)      # octave bands' lower edges [Hz]
REFERENCE = 800
HAMMER_SPEED, LOAD = 0.5, 20.0


def band_shape(f: np.ndarray, h: np.ndarray) -> np.ndarray:
    """(len(BANDS),) mean dB of |h| in each octave band re the 800-1600 Hz band."""
    level = 20 * np.log10(np.maximum(np.abs(h), 1e-300))
    means = np.array([level[(f >= lo) & (f < 2 * lo)].mean() for lo in BANDS])
    return means - means[BANDS.index(REFERENCE)]


def measured_frf(force: np.ndarray, response: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray]:
    n = int(fs / 8)
    f, sfx = sps.csd(force, response, fs=fs, nperseg=n)
    _, sff = sps.welch(force, fs=fs, nperseg=n)
    return f, sfx / np.maximum(sff, 1e-300)


def twin_frf(fmu, parameters: dict, state: str, mass: str, f: np.ndarray) -> np.ndarray:
    from twin.calibration.mode_classes import mass_values
    from twin.calibration.model_modes import BROADBAND_LEVELS, MESH_EXCITATION
    from twin.linearize import linear_model
    from twin.operating import operating_point

    start, inputs = operating_point(HAMMER_SPEED, LOAD)
    lm = linear_model(fmu, parameters={**parameters, **{k: 0.0 for k in BROADBAND_LEVELS}, **start}, inputs=inputs,
                      outputs=[CHANNEL], excitations={"mesh": [MESH_EXCITATION + "[*]"]}, settle=0.02, window=2.5e-3,
                      samples=4)
    b = np.zeros(len(lm.state_names))
    b[lm.state_names.index(state)] = 1.0 / float({**mass_values(fmu, parameters), **parameters}[mass])
    eye = np.eye(lm.A.shape[0])
    return np.array([(lm.C @ np.linalg.solve(2j * np.pi * fi * eye - lm.A, b))[0] for fi in f])


def main(argv=None) -> int:
    from mode_losses import read_run
    from twin.measurements import load_measurements
    from twin.scenario import load_scenario

    dirs = [Path(a) for a in (sys.argv[1:] if argv is None else argv)]
    if not dirs:
        print(__doc__)
        return 2
    print("| rig, seed, record | " + " | ".join(f"{lo}-{2 * lo} Hz" for lo in BANDS) + " |  (dB re 800-1600 Hz: measured / twin)")
    for out in dirs:
        gearboxes = read_run(out)
        if gearboxes is None:
            return 2
        shapes = []
        for g in gearboxes:
            rig, seed = g["rig"], g["seed"]
            files = sorted(out.glob(f"{rig}_{seed}_hammer*.h5"))
            if not files:
                continue
            calibrated = load_scenario(out / f"{rig}_{seed}_cal" / "calibrated.yaml")
            records = load_measurements(files[0])
            for name, (state, mass) in STRUCK_BODY[rig].items():
                if name not in records.names:
                    continue
                rec = records[name]
                f, h = measured_frf(np.asarray(rec["hammer"], float), np.asarray(rec[CHANNEL], float),
                                    float(rec.sample_rate))
                band = (f >= BANDS[0]) & (f < 2 * BANDS[-1])
                m = band_shape(f[band], h[band])
                t = band_shape(f[band], twin_frf(calibrated.fmu_path(), dict(calibrated.parameters), state, mass,
                                                 f[band]))
                shapes.append((m, t))
                print(f"| {rig} {seed} {name} | " + " | ".join(f"{a:+.1f} / {b:+.1f}" for a, b in zip(m, t)) + " |",
                      flush=True)
        if shapes:
            m, t = (np.mean([s[i] for s in shapes], axis=0) for i in (0, 1))
            print(f"| **{out.name}, mean of {len(shapes)}** | " + " | ".join(f"{a:+.1f} / {b:+.1f}" for a, b in zip(m, t))
                  + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
