"""Envelope analysis: the squared-envelope spectrum of a band and the harmonic series it holds.

A rolling-element bearing defect (or any repeated impact) excites the structure's high-frequency
modes once per defect passage; the impacts are too short and too weak to show as lines in the
raw spectrum, where the gear mesh dominates, but the envelope of a band they excite repeats at
the passage frequency. For an outer-race defect that is
``n_balls / 2 * f_shaft * (1 - d / D * cos(phi))``: a fixed, *non-integer* order of the shaft
that carries the inner race, with harmonics. The method is the classical one (band-pass,
analytic signal, spectrum of the squared envelope; Randall and Antoni, "Rolling element bearing
diagnostics - A tutorial", Mech. Syst. Signal Process. 25 (2011) 485-520); the bands are fixed
octaves rather than a kurtogram, since the test asks only whether a series exists in any band.

Pure numpy; units in the docstrings.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from twin.signals._checks import SignalError, as_signal, frequency_band, positive
from twin.signals.spectral import padded_spectrum

#: lowest band edge [Hz]: below it the envelope is the mesh lines' own beating
LOWEST_BAND_HZ = 1000.0


@dataclass(frozen=True)
class EnvelopeSeries:
    """A harmonic series in a record's squared-envelope spectrum.

    ``frequency_hz`` the fundamental [Hz]; ``order`` it in pinion (``shaft_hz``) orders;
    ``harmonics`` how many of the fundamental and its multiples up to ``max_harmonic`` stand out
    (the fundamental counted); ``prominence_db`` the fundamental over the envelope spectrum's
    running median [dB]; ``band_hz`` the demodulated band [Hz]; ``locked_to`` ``"pinion"`` or
    ``"gear"`` when the fundamental is an integer order of that shaft, else ``None``.
    """

    frequency_hz: float
    order: float
    harmonics: int
    prominence_db: float
    band_hz: tuple[float, float]
    locked_to: str | None


def octave_bands(fs: float, lowest: float = LOWEST_BAND_HZ) -> tuple[tuple[float, float], ...]:
    """Octave bands ``(lo, 2 lo)`` [Hz] from ``lowest`` up to 0.45 ``fs`` (the last one cut there)."""
    fs = positive(fs, "fs")
    bands, lo = [], float(lowest)
    while lo < 0.4 * fs:
        bands.append((lo, min(2.0 * lo, 0.45 * fs)))
        lo *= 2.0
    return tuple(bands)


def squared_envelope_spectrum(x, fs: float, band: tuple[float, float], *, fmax: float | None = None,
                              pad: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """The amplitude spectrum of the squared envelope of ``x`` band-passed to ``band``.

    Parameters
    ----------
    x : (n,) array
        Signal [unit], sampled at ``fs`` [Hz].
    band : (lo, hi)
        Band demodulated [Hz], ``0 <= lo < hi <= fs / 2`` (an ideal filter on the FFT).
    fmax : float, optional
        Highest envelope frequency returned [Hz] (default: the band's width).
    pad : int
        The envelope's FFT is zero-padded to ``pad`` times the record or more, to locate lines
        (:func:`twin.signals.spectral.padded_spectrum`).

    Returns
    -------
    f : (m,) array
        Envelope frequencies [Hz], from 0 to ``fmax``.
    amplitude : (m,) array
        Amplitude of the squared envelope [unit**2] (Hann-windowed, mean removed).
    """
    x = as_signal(x, "x", min_length=16)
    fs = positive(fs, "fs")
    lo, hi = _band(band, fs)
    top = hi - lo if fmax is None else positive(fmax, "fmax")
    return _envelope(_spectrum(x, fs), fs, lo, hi, top, pad)


def _band(band, fs: float) -> tuple[float, float]:
    lo, hi = frequency_band(*band)
    if hi > fs / 2:
        raise SignalError(f"band {band!r} reaches above the Nyquist frequency {fs / 2:g} Hz")
    return lo, hi


def _spectrum(x: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """The two-sided FFT of ``x`` less its mean and its frequencies [Hz]: computed once for every
    band demodulated."""
    return np.fft.fft(x - x.mean()), np.fft.fftfreq(x.size, 1.0 / fs)


def _envelope(spectrum, fs: float, lo: float, hi: float, top: float, pad: int) -> tuple[np.ndarray, np.ndarray]:
    spec, f = spectrum
    analytic = np.where((f >= lo) & (f <= hi), 2.0 * spec, 0.0)
    fe, amp = padded_spectrum(np.abs(np.fft.ifft(analytic)) ** 2, fs, pad=pad)
    keep = fe <= top
    return fe[keep], amp[keep]


def envelope_series(x, fs: float, shaft_hz: float, *, gear_ratio: float | None = None,
                    bands=None, min_db: float = 18.0, harmonic_db: float = 6.0, min_harmonics: int = 3,
                    max_harmonic: int = 5, max_order: float = 12.0,
                    median_hz: float = 40.0, lock_orders: float = 0.03,
                    min_unlocked: int = 2) -> tuple[EnvelopeSeries, ...]:
    """Harmonic series in the squared-envelope spectra of ``x`` (n,) [unit] at ``fs`` [Hz].

    In each band (default :func:`octave_bands`) a fundamental is a peak standing ``min_db`` over
    the envelope spectrum's ``median_hz`` running median, at most ``max_order`` pinion orders;
    it makes a series when at least ``min_harmonics`` of it and its multiples up to
    ``max_harmonic`` stand ``harmonic_db`` out (the multiples within 0.5 % plus the location
    tolerance: a bearing's rollers slip by about 1 %). A fundamental that is a multiple of a
    lower series' (in any band) is not a series of its own. Each fundamental is reported once, from the band
    where it stands out most, strongest first. ``shaft_hz`` [Hz] is the pinion's speed;
    ``gear_ratio`` (z1 / z2) classes fundamentals locked to the gear too.
    """
    from scipy.ndimage import median_filter
    from scipy.signal import find_peaks

    x = as_signal(x, "x", min_length=16)
    fs = positive(fs, "fs")
    shaft_hz = positive(shaft_hz, "shaft_hz")
    gear_hz = shaft_hz * positive(gear_ratio, "gear_ratio") if gear_ratio is not None else None
    n = x.size
    lock_tol = max(0.1, 0.3 * fs / n)                     # Hz, as twin.compare's line locking
    found: dict[float, EnvelopeSeries] = {}
    spectrum = _spectrum(x, fs)

    def tol(fq: float) -> float:
        # where a line of frequency fq [Hz] is looked for: the location tolerance and 0.5 %, as
        # a bearing's rollers slip by about 1 %
        return lock_tol + 0.005 * fq

    def multiple(fq: float, base: float) -> bool:
        return abs(fq / base - round(fq / base)) * base <= tol(fq)

    def locked(fq: float) -> str | None:
        # within lock_orders of an integer order of a shaft (in that shaft's orders): a line read
        # on the envelope's grid at a high order drifts with the speed's own wobble
        if abs(fq / shaft_hz - round(fq / shaft_hz)) <= lock_orders:
            return "pinion"
        if gear_hz is not None and abs(fq / gear_hz - round(fq / gear_hz)) <= lock_orders:
            return "gear"
        return None

    for band in (octave_bands(fs) if bands is None else bands):
        lo, hi = _band(band, fs)
        fe, amp = _envelope(spectrum, fs, lo, hi, min(hi - lo, (max_harmonic + 0.5) * max_order * shaft_hz), 4)
        if fe.size < 16 or not np.any(amp > 0):
            continue
        df = float(fe[1] - fe[0])
        level = 20.0 * np.log10(np.maximum(amp, np.max(amp) * 1e-12))
        prom = level - median_filter(level, size=max(5, int(round(median_hz / df))) | 1, mode="nearest")
        peaks, _ = find_peaks(prom, height=harmonic_db)
        if peaks.size == 0:
            continue
        pf, pp = fe[peaks], prom[peaks]
        series = []

        for j in np.argsort(pf):
            f0 = float(pf[j])
            if pp[j] < min_db or f0 < 0.5 * (gear_hz or shaft_hz) or f0 > max_order * shaft_hz:
                continue
            if any(multiple(f0, s) for s in series):
                continue                                  # a harmonic of a lower series
            lines = [h * f0 for h in range(1, max_harmonic + 1) if h * f0 <= fe[-1]
                     and np.any((np.abs(pf - h * f0) <= tol(h * f0)))]
            if len(lines) < min_harmonics:
                continue
            series.append(f0)
            lock = locked(f0)
            # a comb of shaft orders holds a near-multiple of almost anything: a series that is
            # not a shaft's needs min_unlocked of its lines off every shaft order
            if lock is None and sum(locked(fq) is None for fq in lines) < min_unlocked:
                continue
            s = EnvelopeSeries(f0, f0 / shaft_hz, len(lines), float(pp[j]), (lo, hi), lock)
            key = next((k for k in found if abs(k - f0) <= tol(f0)), f0)
            if key not in found or found[key].prominence_db < s.prominence_db:
                found.pop(key, None)
                found[f0] = s
    # a series found in one band at a multiple of a lower series found in another is that series
    out = []
    for s in sorted(found.values(), key=lambda s: s.frequency_hz):
        if not any(round(s.frequency_hz / o.frequency_hz) >= 2 and multiple(s.frequency_hz, o.frequency_hz)
                   for o in out):
            out.append(s)
    return tuple(sorted(out, key=lambda s: -s.prominence_db))
