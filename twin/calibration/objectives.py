"""The calibration objectives of paper Eq. 2: waveform, spectrum and natural frequencies.

* f1 = 1 - Pearson correlation of the time waveforms. Raw waveforms have arbitrary phase, so both
  are synchronously averaged on the pinion shaft angle and aligned by the circular shift that
  maximises their correlation.
* f2 = 1 - Pearson correlation of the spectra. It uses the Welch PSDs in dB over the analysed
  band, because on a linear scale the largest mesh harmonic alone would decide the correlation.
  Both are floored at the measured median level, so the comparison sees the lines and
  resonances, not the measurement's noise floor against the simulation's numerical silence.
* f3 = sum over the measured modes of (f_model - f_measured)^2 [Hz^2], with the model's modes
  matched to the measured ones by a minimum-cost assignment on |ln(f_model / f_measured)|, so a
  missing or extra model mode cannot shift every later pair ("mode swap").
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import linear_sum_assignment

from twin.signals import shaft_angle_from_speed, synchronous_average, welch_psd


def _pearson(a: np.ndarray, b: np.ndarray) -> float:
    a = a - a.mean()
    b = b - b.mean()
    den = float(np.sqrt(np.sum(a * a) * np.sum(b * b)))
    return float(np.sum(a * b) / den) if den > 0 else 0.0


def synchronous_waveform(x: np.ndarray, fs: float, shaft_hz: float, samples_per_rev: int = 512) -> np.ndarray:
    """Time-synchronous average of ``x`` (n,) over revolutions of a shaft at ``shaft_hz``; (samples_per_rev,)."""
    angle = shaft_angle_from_speed(x.size, fs, shaft_hz)
    _, tsa, _ = synchronous_average(x, fs, angle, samples_per_rev=samples_per_rev)
    return tsa


def waveform_mismatch(model: np.ndarray, measured: np.ndarray, fs: float, shaft_hz: float, *,
                      measured_shaft_hz: float | None = None, samples_per_rev: int = 512) -> float:
    """f1 = 1 - max over circular shifts of corr(TSA_model, TSA_measured); 0 is a perfect match."""
    a = synchronous_waveform(np.asarray(model, float), fs, shaft_hz, samples_per_rev)
    b = synchronous_waveform(np.asarray(measured, float), fs, measured_shaft_hz or shaft_hz, samples_per_rev)
    a = (a - a.mean()) / (np.std(a) or 1.0)
    b = (b - b.mean()) / (np.std(b) or 1.0)
    # circular cross-correlation of the two one-revolution waveforms, via FFT, evaluated on an
    # 8x finer shift grid: at 512 samples/rev half a sample of misalignment on the 19th mesh
    # harmonic would otherwise cost up to 0.007 of correlation
    up = 8
    xc = np.fft.irfft(np.fft.rfft(a) * np.conj(np.fft.rfft(b)), n=up * a.size) * up / a.size
    return float(1.0 - np.max(xc))


def spectrum_mismatch(model: np.ndarray, measured: np.ndarray, fs: float, *, fmin: float = 10.0,
                      fmax: float = 5000.0, resolution: float = 2.0) -> float:
    """f2 = 1 - corr of the Welch PSDs in dB over [fmin, fmax] Hz.

    ``resolution`` [Hz] is coarsened for short records so Welch still averages >= 4 segments.
    """
    n = min(len(model), len(measured))
    resolution = max(resolution, 4.0 * fs / n)
    f, pm = welch_psd(np.asarray(model, float), fs, resolution=resolution)
    _, pp = welch_psd(np.asarray(measured, float), fs, resolution=resolution)
    band = (f >= fmin) & (f <= fmax)
    # Both spectra are floored at the measured median level: below it a measurement shows its
    # noise floor, a simulation shows numerical silence (-150 dB), and the dB correlation would
    # compare the two floors instead of the lines and resonances that carry the information.
    floor = max(float(np.median(pp[band])), 1e-30)
    return float(1.0 - _pearson(10 * np.log10(np.maximum(pm[band], floor)),
                                10 * np.log10(np.maximum(pp[band], floor))))


def match_modes(model_hz: np.ndarray, measured_hz: np.ndarray) -> np.ndarray:
    """Index of the model mode matched to each measured mode, shape (k,).

    Minimum total |ln(f_model/f_measured)| over one-to-one assignments (Hungarian algorithm);
    the model list should hold a few more modes than the measured one.
    """
    model_hz = np.asarray(model_hz, float)
    measured_hz = np.asarray(measured_hz, float)
    if model_hz.size < measured_hz.size:
        raise ValueError(f"{model_hz.size} model modes cannot match {measured_hz.size} measured modes")
    cost = np.abs(np.log(model_hz[None, :] / measured_hz[:, None]))
    rows, cols = linear_sum_assignment(cost)
    out = np.empty(measured_hz.size, dtype=int)
    out[rows] = cols
    return out


def frequency_mismatch(model_hz: np.ndarray, measured_hz: np.ndarray) -> float:
    """f3 = sum (f_model - f_measured)^2 over the measured modes [Hz^2], after :func:`match_modes`."""
    idx = match_modes(model_hz, measured_hz)
    return float(np.sum((np.asarray(model_hz)[idx] - np.asarray(measured_hz)) ** 2))


def estimate_shaft_hz(x: np.ndarray, fs: float, nominal_hz: float, teeth: int, *, search: float = 0.06) -> float:
    """Actual shaft speed [Hz] from the gear-mesh line: the largest spectral peak within
    +-``search`` (relative) of ``teeth * nominal_hz``, refined by a zero-padded FFT, divided by ``teeth``.
    An induction motor slips under load, so the nominal drive setting is not the shaft speed.
    """
    x = np.asarray(x, float) - np.mean(x)
    nfft = 1 << int(np.ceil(np.log2(16 * x.size)))
    spec = np.abs(np.fft.rfft(x * np.hanning(x.size), n=nfft))
    f = np.fft.rfftfreq(nfft, 1.0 / fs)
    gmf = teeth * nominal_hz
    band = (f >= gmf * (1 - search)) & (f <= gmf * (1 + search))
    if not band.any():
        raise ValueError(f"the gear-mesh band around {gmf:.1f} Hz is outside the spectrum (fs={fs} Hz)")
    return float(f[band][np.argmax(spec[band])] / teeth)
