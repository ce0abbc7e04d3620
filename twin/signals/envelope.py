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

from dataclasses import dataclass, replace

import numpy as np

from twin.signals._checks import SignalError, as_signal, frequency_band, positive
from twin.signals.spectral import padded_spectrum

#: lowest band edge [Hz]: below it the envelope is the mesh lines' own beating
LOWEST_BAND_HZ = 1000.0
#: a series' fundamental over the envelope spectrum's running median [dB] for one record alone
SERIES_DB = 18.0
#: the same when a run-up of the gearbox holds a series at the same order
#: (:func:`order_envelope_series`): healthy records' unlocked series stood 12-17 dB in one steady
#: record, and none of them at a fixed order through a run-up (docs/diagnosis.md)
CONFIRMED_DB = 12.0


@dataclass(frozen=True)
class EnvelopeSeries:
    """A harmonic series in a record's squared-envelope spectrum.

    ``frequency_hz`` the fundamental [Hz]; ``order`` it in pinion (``shaft_hz``) orders;
    ``harmonics`` how many of the fundamental and its multiples up to ``max_harmonic`` stand out
    (the fundamental counted); ``prominence_db`` the fundamental over the envelope spectrum's
    running median [dB]; ``band_hz`` the demodulated band [Hz]; ``locked_to`` ``"pinion"`` or
    ``"gear"`` when the fundamental is an integer order of that shaft, else ``None``;
    ``order_tol`` how closely the fundamental is located [pinion orders] (the spectrum's
    location tolerance).
    """

    frequency_hz: float
    order: float
    harmonics: int
    prominence_db: float
    band_hz: tuple[float, float]
    locked_to: str | None
    order_tol: float = 0.0

    def confirms(self, other: "EnvelopeSeries") -> bool:
        """Whether ``other`` (of another record of the gearbox, a run-up) is this series: their
        fundamentals within both spectra's location tolerances."""
        return abs(self.order - other.order) <= self.order_tol + other.order_tol


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
                    bands=None, min_db: float = SERIES_DB, harmonic_db: float = 6.0, min_harmonics: int = 3,
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
    x = as_signal(x, "x", min_length=16)
    fs = positive(fs, "fs")
    shaft_hz = positive(shaft_hz, "shaft_hz")
    gear_hz = shaft_hz * positive(gear_ratio, "gear_ratio") if gear_ratio is not None else None
    rule = _SeriesRule(shaft_hz, gear_hz, max(0.1, 0.3 * fs / x.size), min_db, harmonic_db, min_harmonics,
                       max_harmonic, max_order, median_hz, lock_orders, min_unlocked)
    spectrum = _spectrum(x, fs)
    found: dict[float, EnvelopeSeries] = {}
    for band in (octave_bands(fs) if bands is None else bands):
        lo, hi = _band(band, fs)
        fe, amp = _envelope(spectrum, fs, lo, hi, min(hi - lo, rule.top), 4)
        rule.search(fe, amp, (lo, hi), found)
    return rule.distinct(found)


def order_envelope_series(x, fs: float, shaft_hz, *, gear_ratio: float | None = None, bands=None,
                          min_speed: float = 0.4, min_db: float = CONFIRMED_DB, harmonic_db: float = 6.0,
                          min_harmonics: int = 3, max_harmonic: int = 5, max_order: float = 12.0,
                          median_orders: float = 2.0, lock_orders: float = 0.03,
                          min_unlocked: int = 2) -> tuple[EnvelopeSeries, ...]:
    """Harmonic series in the squared-envelope *order* spectra of a run-up ``x`` (n,) [unit] at
    ``fs`` [Hz] with the pinion speed ``shaft_hz`` (n,) [Hz] per sample.

    Repeated impacts at a fixed non-integer order of a shaft (a bearing defect) stay at that
    order through a run-up, where anything fixed in frequency smears across orders: the band's
    squared envelope (as :func:`squared_envelope_spectrum`, low-passed to the highest harmonic
    sought at the top speed) is resampled to uniform pinion angle over the stretch where the
    speed is at least ``min_speed`` of its highest, and its spectrum taken in pinion orders.
    The series are found as :func:`envelope_series` finds them, with orders for hertz (a
    ``median_orders`` running median): ``frequency_hz`` is then the mean speed of the stretch
    times the order. Raises :class:`SignalError` for a speed that is not positive or not as
    long as ``x``.
    """
    x = as_signal(x, "x", min_length=16)
    fs = positive(fs, "fs")
    speed = as_signal(shaft_hz, "shaft_hz", min_length=16)
    if speed.size != x.size:
        raise SignalError(f"shaft_hz has {speed.size} samples, x {x.size}: one speed per sample is needed")
    if not np.all(speed > 0):
        raise SignalError(f"shaft_hz reaches {float(np.min(speed)):g} Hz: the speed must stay positive")
    keep = np.flatnonzero(speed >= min_speed * float(np.max(speed)))
    x, speed = x[keep[0]:keep[-1] + 1], speed[keep[0]:keep[-1] + 1]
    revs = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) / fs)])    # [rev]
    if revs[-1] < 8:
        raise SignalError(f"the run-up above {min_speed:g} of its top speed holds {revs[-1]:.1f} revolutions; "
                          "at least 8 are needed for an order spectrum")
    top_orders = (max_harmonic + 0.5) * max_order
    per_rev = int(2 ** np.ceil(np.log2(2.5 * top_orders * float(np.max(speed)) / float(np.min(speed)))))
    grid = np.arange(0.0, revs[-1], 1.0 / per_rev)
    mean_hz = float(revs[-1] * fs / max(x.size - 1, 1))
    rule = _SeriesRule(1.0, positive(gear_ratio, "gear_ratio") if gear_ratio is not None else None,
                       max(0.1 / mean_hz, 0.3 / revs[-1]), min_db, harmonic_db, min_harmonics, max_harmonic,
                       max_order, median_orders, lock_orders, min_unlocked)
    spectrum = _spectrum(x, fs)
    found: dict[float, EnvelopeSeries] = {}
    for band in (octave_bands(fs) if bands is None else bands):
        lo, hi = _band(band, fs)
        spec, f = spectrum
        env = np.abs(np.fft.ifft(np.where((f >= lo) & (f <= hi), 2.0 * spec, 0.0))) ** 2
        # low-passed before the angle resampling, which would fold faster envelope content in
        e = np.fft.rfft(env - env.mean())
        e[np.fft.rfftfreq(env.size, 1.0 / fs) > top_orders * float(np.max(speed))] = 0.0
        fo, amp = padded_spectrum(np.interp(grid, revs, np.fft.irfft(e, env.size)), float(per_rev), pad=4)
        sel = fo <= top_orders
        rule.search(fo[sel], amp[sel], (lo, hi), found)
    return tuple(replace(s, frequency_hz=s.order * mean_hz) for s in rule.distinct(found))


@dataclass(frozen=True)
class _SeriesRule:
    """The series search of :func:`envelope_series`, in the unit of the spectrum it reads: hertz
    (``shaft`` the pinion speed [Hz]) or pinion orders (``shaft`` 1)."""

    shaft: float
    gear: float | None
    lock_tol: float
    min_db: float
    harmonic_db: float
    min_harmonics: int
    max_harmonic: int
    max_order: float
    median: float
    lock_orders: float
    min_unlocked: int

    @property
    def top(self) -> float:
        """Highest envelope frequency searched (the last harmonic of the highest fundamental)."""
        return (self.max_harmonic + 0.5) * self.max_order * self.shaft

    def tol(self, fq: float) -> float:
        # where a line of frequency fq is looked for: the location tolerance and 0.5 %, as a
        # bearing's rollers slip by about 1 %
        return self.lock_tol + 0.005 * fq

    def multiple(self, fq: float, base: float) -> bool:
        return abs(fq / base - round(fq / base)) * base <= self.tol(fq)

    def locked(self, fq: float) -> str | None:
        # within lock_orders of an integer order of a shaft (in that shaft's orders): a line read
        # on the envelope's grid at a high order drifts with the speed's own wobble
        if abs(fq / self.shaft - round(fq / self.shaft)) <= self.lock_orders:
            return "pinion"
        if self.gear is not None and abs(fq / self.gear - round(fq / self.gear)) <= self.lock_orders:
            return "gear"
        return None

    def search(self, fe: np.ndarray, amp: np.ndarray, band: tuple[float, float],
               found: dict[float, EnvelopeSeries]) -> None:
        """Add the series of one band's envelope spectrum (``fe``, ``amp`` (m,)) to ``found``
        (keyed by fundamental; the band where a fundamental stands out most kept)."""
        from scipy.ndimage import median_filter
        from scipy.signal import find_peaks

        if fe.size < 16 or not np.any(amp > 0):
            return
        df = float(fe[1] - fe[0])
        level = 20.0 * np.log10(np.maximum(amp, np.max(amp) * 1e-12))
        prom = level - median_filter(level, size=max(5, int(round(self.median / df))) | 1, mode="nearest")
        peaks, _ = find_peaks(prom, height=self.harmonic_db)
        if peaks.size == 0:
            return
        pf, pp = fe[peaks], prom[peaks]
        series = []
        for j in np.argsort(pf):
            f0 = float(pf[j])
            if pp[j] < self.min_db or f0 < 0.5 * (self.gear or self.shaft) or f0 > self.max_order * self.shaft:
                continue
            if any(self.multiple(f0, s) for s in series):
                continue                                  # a harmonic of a lower series
            lines = [h * f0 for h in range(1, self.max_harmonic + 1) if h * f0 <= fe[-1]
                     and np.any((np.abs(pf - h * f0) <= self.tol(h * f0)))]
            if len(lines) < self.min_harmonics:
                continue
            series.append(f0)
            lock = self.locked(f0)
            # a comb of shaft orders holds a near-multiple of almost anything: a series that is
            # not a shaft's needs min_unlocked of its lines off every shaft order
            if lock is None and sum(self.locked(fq) is None for fq in lines) < self.min_unlocked:
                continue
            s = EnvelopeSeries(f0, f0 / self.shaft, len(lines), float(pp[j]), band, lock,
                               self.lock_tol / self.shaft)
            key = next((k for k in found if abs(k - f0) <= self.tol(f0)), f0)
            if key not in found or found[key].prominence_db < s.prominence_db:
                found.pop(key, None)
                found[f0] = s

    def distinct(self, found: dict[float, EnvelopeSeries]) -> tuple[EnvelopeSeries, ...]:
        """The series strongest first, less those at a multiple of a lower one found in another band."""
        out = []
        for s in sorted(found.values(), key=lambda s: s.frequency_hz):
            if not any(round(s.frequency_hz / o.frequency_hz) >= 2 and self.multiple(s.frequency_hz, o.frequency_hz)
                       for o in out):
                out.append(s)
        return tuple(sorted(out, key=lambda s: -s.prominence_db))
