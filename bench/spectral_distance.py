"""A floor-aware, gain-free log-spectral distance between a model's and a measurement's vibration.

Written apart from the code it judges: numpy and scipy only, nothing from ``twin`` (in
particular not ``twin.compare``), so a change to the twin's own comparison cannot move this
yardstick.

    d = log_spectral_distance(model, measured, fs)           # dB, 0 = same spectral shape

From the shell (``make demo`` after step 8): each record of MODELS against the last stretch of
the same length of the measured record::

    python bench/spectral_distance.py MEASURED.h5 --record steady --models MODELS.h5 [--channel C]

Definition (``resolution`` Hz Welch PSDs, Hann, 50 % overlap, over [fmin, fmax]):

1. **Measurement floor.** The measured PSD smoothed by a running median over a third of an
   octave; its lowest value over the band is the floor ``N`` (the measurement's noise cannot lie
   above the quietest stretch of its spectrum).
2. **Floor-aware.** Both levels are floored 3 dB above ``N`` (a Welch estimate of noise alone
   rarely gets there): bins where the measurement is at its floor
   and the model below it count as equal (a model has no acquisition noise, and its numerical
   silence 100 dB down is not a discrepancy); a model above the floor where the measurement is
   not still counts.
3. **Gain-free.** The model level is shifted by the median dB difference over the bins where the
   measurement stands above the floor: a sensor gain or an excitation level off by a constant
   factor is not counted; the shape is (lines, floor, humps).
4. ``d`` = RMS over the band of the dB difference.

:func:`spectral_distance_report` also returns the applied gain and the share of bins above the
floor.
"""
from __future__ import annotations

import numpy as np
from scipy import signal as sps


def _psd(x: np.ndarray, fs: float, resolution: float) -> tuple[np.ndarray, np.ndarray]:
    x = np.asarray(x, float)
    nperseg = int(min(x.size, round(fs / resolution)))
    return sps.welch(x - x.mean(), fs=fs, window="hann", nperseg=nperseg, noverlap=nperseg // 2,
                     detrend="constant", scaling="density")


def _running_median_third_octave(f: np.ndarray, p: np.ndarray) -> np.ndarray:
    out = np.empty_like(p)
    lo = np.searchsorted(f, f * 2 ** (-1 / 6))
    hi = np.searchsorted(f, f * 2 ** (1 / 6), side="right")
    for i in range(p.size):
        out[i] = np.median(p[lo[i]:max(hi[i], lo[i] + 1)])
    return out


def spectral_distance_report(model, measured, fs: float, *, fmin: float = 20.0, fmax: float = 5000.0,
                             resolution: float = 4.0) -> dict:
    """Distance [dB] and its parts (see the module docstring)."""
    n = min(len(model), len(measured))
    f, pm = _psd(np.asarray(model, float)[:n], fs, resolution)
    _, pp = _psd(np.asarray(measured, float)[:n], fs, resolution)
    band = (f >= fmin) & (f <= min(fmax, fs / 2))
    f, pm, pp = f[band], pm[band], pp[band]
    noise = float(np.min(_running_median_third_octave(f, pp)))
    noise = max(noise, 1e-300)
    floor_db = 10 * np.log10(2.0 * noise)
    lp = np.maximum(10 * np.log10(np.maximum(pp, 1e-300)), floor_db)
    lm_raw = 10 * np.log10(np.maximum(pm, 1e-300))
    above = lp > floor_db
    gain = float(np.median((lp - lm_raw)[above])) if above.any() else 0.0
    lm = np.maximum(lm_raw + gain, floor_db)
    d = lp - lm
    return {"distance_db": float(np.sqrt(np.mean(d ** 2))), "gain_db": gain,
            "above_floor": float(np.mean(above)), "noise_psd": noise, "bins": int(f.size)}


def log_spectral_distance(model, measured, fs: float, **kwargs) -> float:
    """Floor-aware, gain-free log-spectral distance [dB] (see the module docstring)."""
    return spectral_distance_report(model, measured, fs, **kwargs)["distance_db"]


def _read(path: str, channel: str) -> list[tuple[str, np.ndarray, float]]:
    """(record name, channel samples, sample rate [Hz]) of every record of a measurement file
    (the HDF5 layout of ``docs/measurements.md``, read with h5py alone)."""
    import h5py
    out = []
    with h5py.File(path, "r") as f:
        for name, g in f["records"].items():
            fs = float(g.attrs["sample_rate"])
            out.append((name, np.asarray(g[channel][...], float), fs))
    return out


def main(argv=None) -> int:
    import argparse
    ap = argparse.ArgumentParser(description="Floor-aware, gain-free spectral distance of models to a record")
    ap.add_argument("measured", help="measurement file (HDF5)")
    ap.add_argument("--record", required=True, help="the measured record")
    ap.add_argument("--models", required=True, help="measurement file whose records are model signals")
    ap.add_argument("--channel", default="accel_pinion_casing")
    args = ap.parse_args(argv)
    rec = {n: (x, fs) for n, x, fs in _read(args.measured, args.channel)}
    if args.record not in rec:
        ap.error(f"no record {args.record!r} in {args.measured} (it has {', '.join(rec)})")
    x, fs = rec[args.record]
    rows = []
    print(f"floor-aware, gain-free spectral distance (bench/spectral_distance.py, 20-5000 Hz, 4 Hz) to "
          f"{args.measured} record {args.record!r}")
    print(f"{'model':<10} {'distance [dB]':>13} {'gain [dB]':>9} {'bins above floor':>16}")
    for name, y, fy in _read(args.models, args.channel):
        if fy != fs:
            ap.error(f"model {name!r} is sampled at {fy} Hz, the record at {fs} Hz")
        r = spectral_distance_report(y, x[-y.size:], fs)
        rows.append(r["distance_db"])
        print(f"{name:<10} {r['distance_db']:>13.2f} {r['gain_db']:>+9.1f} {100 * r['above_floor']:>15.0f} %")
    if len(rows) > 1 and rows[0] > 0:
        print(f"change: {rows[-1] - rows[0]:+.2f} dB ({100 * (rows[-1] - rows[0]) / rows[0]:+.0f} %)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
