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


def _levels_on_orders(x: np.ndarray, fs: float, speed: float, orders: np.ndarray, resolution: float
                      ) -> np.ndarray:
    """PSD level [dB] of ``x`` at ``orders`` of a shaft turning at ``speed`` [Hz] (linear in dB
    between Welch bins)."""
    f, p = _psd(x, fs, resolution)
    return np.interp(orders * speed, f, 10 * np.log10(np.maximum(p, 1e-300)))


def _floor_db(x: np.ndarray, fs: float, resolution: float, fmin: float, fmax: float) -> float:
    """3 dB above the lowest third-octave running median of the PSD over the band [dB]."""
    f, p = _psd(x, fs, resolution)
    band = (f >= fmin) & (f <= min(fmax, fs / 2))
    return 10 * np.log10(2.0 * max(float(np.min(_running_median_third_octave(f[band], p[band]))), 1e-300))


def change_distance_report(model, model_ref, measured, measured_ref, fs: float, speeds, *, fmin: float = 20.0,
                           fmax: float = 5000.0, resolution: float = 4.0) -> dict:
    """Distance [dB] between the change a model shows and the change measured.

    ``measured`` and ``measured_ref``: a record and a reference record of the same gearbox (the
    one before the change); ``model`` and ``model_ref``: the model at the same two operating
    points; ``speeds``: their pinion speeds (model, model_ref, measured, measured_ref) [Hz]. A
    model-form error common to both records (a missing mode, a wrong path) cancels in each
    change; what is left is the change the model does not show.

    1. Each signal's PSD level on a common grid of shaft orders (the records turn at speeds a
       few 0.1 % apart, which would set their high mesh harmonics bins apart), over the orders
       of [fmin, fmax] at the measured record's speed.
    2. Floor-aware: the measured levels floored at the higher of the two records' floors (3 dB
       above the lowest third-octave running median); the model's at that floor less the
       model's gain (the median level difference of model_ref to measured_ref above it).
    3. Gain-free: each change less its median over the bins where either level stands above
       its floor (a sensor gain that differs between two records is not a change); bins at the
       floor in both stay 0.
    4. The RMS over the grid of measured change minus model change.
    Returns ``distance_db``, ``measured_change_db`` (the RMS of the measured change itself:
    the distance of a model that shows no change) and ``bins``.
    """
    s_m, s_mr, s_x, s_xr = (float(v) for v in speeds)
    df = resolution / 2.0
    orders = np.arange(fmin, min(fmax, fs / 2) + df, df) / s_x
    sig = {k: np.asarray(v, float) for k, v in
           dict(model=model, model_ref=model_ref, measured=measured, measured_ref=measured_ref).items()}
    lev = {"model": _levels_on_orders(sig["model"], fs, s_m, orders, resolution),
           "model_ref": _levels_on_orders(sig["model_ref"], fs, s_mr, orders, resolution),
           "measured": _levels_on_orders(sig["measured"], fs, s_x, orders, resolution),
           "measured_ref": _levels_on_orders(sig["measured_ref"], fs, s_xr, orders, resolution)}
    floor = max(_floor_db(sig["measured"], fs, resolution, fmin, fmax),
                _floor_db(sig["measured_ref"], fs, resolution, fmin, fmax))
    above_ref = lev["measured_ref"] > floor
    gain = float(np.median((lev["measured_ref"] - lev["model_ref"])[above_ref])) if above_ref.any() else 0.0
    m_floor = floor - gain
    xm, xr = np.maximum(lev["measured"], floor), np.maximum(lev["measured_ref"], floor)
    sm, sr = np.maximum(lev["model"], m_floor), np.maximum(lev["model_ref"], m_floor)
    live_x = (xm > floor) | (xr > floor)
    live_s = (sm > m_floor) | (sr > m_floor)
    dx, ds = xm - xr, sm - sr
    # bins at the floor in both records of a pair stay unchanged whatever the gain
    dx = np.where(live_x, dx - (float(np.median(dx[live_x])) if live_x.any() else 0.0), 0.0)
    ds = np.where(live_s, ds - (float(np.median(ds[live_s])) if live_s.any() else 0.0), 0.0)
    return {"distance_db": float(np.sqrt(np.mean((dx - ds) ** 2))),
            "measured_change_db": float(np.sqrt(np.mean(dx ** 2))), "bins": int(orders.size)}


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
