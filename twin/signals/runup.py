"""Natural frequencies from a speed run-up, with orders, fixed lines and resonances told apart.

A run-up record holds three kinds of content (see :mod:`twin.signals.survey`). The analysis
separates them with what distinguishes them physically, not with thresholds on one record:

1. **Spectrogram.** Hann slices of ``T`` s (50 % overlap); each slice is expressed in dB re its own
   local floor (the running median over one octave), so levels do not depend on the analysed band
   and the overall growth of the vibration with speed drops out.
2. **Orders.** The level along every track ``f = o * speed(t)`` on a fine order grid; an order whose
   track stands above the floor in most slices is locked to the shaft. Its track is masked.
3. **Stationary spectrum.** The median over the slices of what is left: content that sweeps with
   speed occupies a bin in few slices and drops out; content fixed in frequency stays.
4. **Lines against resonances.** A fixed peak is either a deterministic line (a drive frequency) or
   a resonance driven by broadband (random) excitation. A deterministic line has the same level in
   every slice; a bin of a randomly excited resonance fluctuates from slice to slice like any
   random process (about 5.6 dB standard deviation for a single periodogram). A narrow, steady peak
   is a line; it is removed before the resonances are searched, so a resonance under a line is
   still found. Everything else that stands above the floor is a resonance: a hump as wide as its
   damping makes it.
5. **Frequency and damping** of each resonance by a single-mode fit to the stationary spectrum
   (dB), within the hump.

Steps 4 and 5 are in :mod:`twin.signals.peaks`.

Frequencies in Hz, angles in rad, levels in dB re the local floor.
"""
from __future__ import annotations

import warnings

import numpy as np
from scipy import signal as sps

from twin.signals._checks import SignalError, as_signal, positive, same_length
from twin.signals.peaks import _cut_lines, _find_lines, _find_modes, _parabolic
from twin.signals.survey import ModalSurvey, Order

#: Scatter [dB] of the [1 2 1]-smoothed median of M Hann periodograms of random content is
#: NOISE_SD_DB / sqrt(M) (measured on white noise for M = 11, 23, 47).
NOISE_SD_DB = 4.6
#: Peaks of pure noise exceed this many of those standard deviations in prominence about once
#: per 10^4 bins (same measurement).
FALSE_PEAK_SIGMAS = 7.0


def _slices(x: np.ndarray, fs: float, nperseg: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(f (nf,), power (nf, nt) [unit^2/Hz], start index (nt,)) of Hann slices, 50 % overlap."""
    step = nperseg // 2
    f, _, p = sps.spectrogram(x, fs=fs, window="hann", nperseg=nperseg, noverlap=nperseg - step,
                              detrend="constant", scaling="density", mode="psd")
    starts = np.arange(p.shape[1]) * step
    return f, p, starts


def _slice_speeds(angle: np.ndarray, starts: np.ndarray, nperseg: int, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """Mean speed [Hz] in each slice and the speed change across it [Hz], from the shaft angle."""
    half = nperseg // 2
    a0, am, a1 = angle[starts], angle[starts + half], angle[starts + nperseg - 1]
    s1 = (am - a0) / (2 * np.pi * half / fs)
    s2 = (a1 - am) / (2 * np.pi * (nperseg - 1 - half) / fs)
    return (a1 - a0) / (2 * np.pi * (nperseg - 1) / fs), 2.0 * np.abs(s2 - s1)


def _local_floor(level: np.ndarray, f: np.ndarray, fmin: float, fmax: float) -> np.ndarray:
    """Running median [dB] over one octave around each bin, per slice; level (nf, nt) -> (nf, nt).

    Computed at anchors 1/6 octave apart and interpolated in log frequency. At least 11 bins
    enter each median, so low frequencies with few bins per octave still get a stable floor.
    """
    df = f[1] - f[0]
    lo = max(fmin / 2, df)
    anchors = lo * 2.0 ** (np.arange(0, np.log2(fmax * 1.5 / lo) + 1 / 6, 1 / 6))
    floor = np.empty((anchors.size, level.shape[1]))
    for i, fa in enumerate(anchors):
        c = int(round(fa / df))
        hw = max(5, int(round(fa * (np.sqrt(2) - 1) / df)))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            floor[i] = np.nanmedian(level[max(1, c - hw): c + hw + 1], axis=0)
    out = np.empty_like(level)
    logf = np.log(np.maximum(f, df / 2))
    for t in range(level.shape[1]):
        ok = np.isfinite(floor[:, t])
        out[:, t] = np.interp(logf, np.log(anchors[ok]), floor[ok, t]) if ok.any() else 0.0
    return out


def _find_orders(x: np.ndarray, fs: float, angle: np.ndarray, speed: np.ndarray, fmin: float, fmax: float,
                 norm: np.ndarray, f: np.ndarray) -> tuple[Order, ...]:
    """Orders of the shaft, from the order spectrum of the angularly resampled record.

    Resampled at equal angle steps, content locked to the shaft falls on sharp lines at its
    order while fixed-frequency content (lines, resonances) smears over ``f/speed``. A line of the
    order spectrum that clears its local floor (running median over +-1 order) by more than the
    order spectrum's own peaks of noise do is an order.
    """
    from twin.signals.tsa import angular_resample

    max_order = fmax / float(np.median(speed))
    spr = int(2 ** np.ceil(np.log2(2.5 * max_order)))
    _, xa = angular_resample(x, fs, angle, spr)
    n_revs = xa.size // spr
    # Welch in the angle domain: segments of 1/16 of the record (at least 4 revolutions) trade
    # order resolution for a stable floor; an order's line stays within about one bin even when
    # its amplitude and phase change through the run-up.
    seg_revs = max(4, n_revs // 16)
    if n_revs < 2 * seg_revs:
        return ()
    orders, _, psd = sps.spectrogram(xa, fs=spr, window="hann", nperseg=seg_revs * spr,
                                     noverlap=seg_revs * spr // 2, detrend="constant", mode="psd")
    keep = (orders * float(np.max(speed)) >= fmin) & (orders <= max_order)
    orders, psd = orders[keep], psd[keep]
    if orders.size < 16 or psd.shape[1] < 3:
        return ()
    # each segment against its own floor (running median over +-2 orders): a segment at low speed
    # holds far more fixed-frequency energy per order than one at high speed, so the floor of a
    # plain average would be set by the slowest revolutions
    seg_db = 10 * np.log10(np.maximum(psd, np.finfo(float).tiny))
    per_order = max(1, int(round(1.0 / (orders[1] - orders[0]))))
    seg_db -= np.apply_along_axis(_running_median, 0, seg_db, 4 * per_order + 1)
    excess = np.median(seg_db, axis=1)
    threshold = max(6.0, FALSE_PEAK_SIGMAS * NOISE_SD_DB / np.sqrt(psd.shape[1]))
    peaks, _ = sps.find_peaks(excess, height=threshold)
    out = []
    for p in peaks:
        o = _parabolic(orders, excess, p)
        # persistence: the share of the time slices in which the track stands above the local floor
        track = o * speed
        inside = (track >= f[1]) & (track <= f[-2])
        if not inside.any():
            continue
        cols = np.flatnonzero(inside)
        k = np.clip(np.round(track[cols] / (f[1] - f[0])).astype(int), 1, f.size - 2)
        lv = np.maximum(np.maximum(norm[k - 1, cols], norm[k, cols]), norm[k + 1, cols])
        out.append(Order(round(o, 4), float(excess[p]), float(np.mean(lv > 3.0))))
    return tuple(out)


def _running_median(v: np.ndarray, width: int) -> np.ndarray:
    width = int(width) | 1
    if width >= v.size:
        return np.full_like(v, np.median(v))
    pad = width // 2
    padded = np.pad(v, pad, mode="reflect")
    return np.median(np.lib.stride_tricks.sliding_window_view(padded, width), axis=1)


#: An order's track is masked in the slices where it sweeps over at most this many bins: there it
#: is a narrow peak the median could keep; a faster sweep spreads it thinly over many bins (and
#: a dense comb of such tracks, e.g. from flank roughness, would otherwise mask everything).
MASK_MAX_SWEEP_BINS = 8
#: Orders masked: at most this many, the strongest, each at least MASK_MIN_DB above the floor.
MASK_MAX_ORDERS = 24
MASK_MIN_DB = 10.0


def _mask_orders(shape, f: np.ndarray, speed: np.ndarray, spread: np.ndarray, orders) -> np.ndarray:
    masked = np.zeros(shape, dtype=bool)
    df = f[1] - f[0]
    strong = sorted((o for o in orders if o.level_db >= MASK_MIN_DB), key=lambda o: -o.level_db)[:MASK_MAX_ORDERS]
    for o in strong:
        sweep = o.order * spread
        half = 0.5 * sweep + 2.0 * df
        on = (np.abs(f[:, None] - o.order * speed[None, :]) <= half[None, :]) & (sweep <= MASK_MAX_SWEEP_BINS * df)
        masked |= on
    return masked


def analyse_runup(x, fs: float, angle=None, *, fmin: float | None = None, fmax: float | None = None,
                  resolution: float | None = None) -> ModalSurvey:
    """Modes, fixed lines and orders of a run-up (or of any record with a shaft angle).

    Parameters
    ----------
    x : (n,) array
        Vibration [unit, e.g. m/s**2].
    fs : float
        Sampling rate [Hz].
    angle : (n,) array, optional
        Unwrapped shaft angle [rad] (from an encoder, a tachometer or an integrated speed). Without
        it no order can be found and a steady line cannot be told from a shaft harmonic.
    fmin, fmax : float, optional
        Band [Hz]; default 4 bins to ``min(0.4 fs, 10 kHz)``. The result inside the band does not
        depend on the band's edges (levels are read against a local floor).
    resolution : float, optional
        Bin spacing [Hz] of the slices; default from the record: twelve slice lengths per record
        (a 6 s run-up gives 0.5 s slices, 2 Hz), at most 1 s.

    Returns
    -------
    ModalSurvey
        ``modes`` (ascending frequency), ``lines``, ``orders``, and the stationary spectrum.
    """
    x = as_signal(x, "x", min_length=16)
    fs = positive(fs, "fs")
    duration = x.size / fs
    if resolution is None:
        seg = float(np.clip(duration / 12.0, 0.05, 1.0))
    else:
        seg = 1.0 / positive(resolution, "resolution")
    nperseg = int(round(seg * fs))
    if 5 * nperseg // 2 > x.size:
        raise SignalError(f"a {duration:.3g} s record gives fewer than 4 slices of {seg:.3g} s; "
                          "use a coarser resolution or a longer record")
    df = fs / nperseg
    fmax = float(min(0.4 * fs, 10_000.0) if fmax is None else fmax)
    fmin = float(4 * df if fmin is None else fmin)
    if not (0 <= fmin < fmax <= fs / 2):
        raise SignalError(f"need 0 <= fmin < fmax <= fs/2 = {fs / 2:g} Hz, got fmin={fmin:g}, fmax={fmax:g}")
    notes: list[str] = []

    view = _View.of(x, fs, nperseg, angle, fmin, fmax)
    notes: list[str] = []
    orders: tuple[Order, ...] = ()
    if view.speed is None:
        notes.append("no shaft angle: speed-locked orders cannot be separated; narrow steady peaks are reported "
                     "as lines")
    else:
        sweep = float(view.speed.max() / view.speed.min())
        if sweep < 1.2:
            notes.append(f"the speed changes by only {100 * (sweep - 1):.0f} % over the record: orders and fixed "
                         "lines cannot be told apart by their tracks; peaks at shaft harmonics are reported as orders")
        else:
            orders = _find_orders(x, fs, angle, view.speed, fmin, fmax, view.norm, view.f)
    view.mask(orders)
    f, band = view.f, view.band
    if band.size < 8:
        raise SignalError(f"the band [{fmin:g}, {fmax:g}] Hz holds fewer than 8 bins at {df:g} Hz")
    # What noise is left in the smoothed stationary spectrum sets the prominence a peak must have:
    # the [1 2 1]-smoothed median of M single-slice periodograms of random content scatters by
    # NOISE_SD_DB / sqrt(M) dB, and a peak of pure noise rarely (about once in 10^4 bins) reaches
    # FALSE_PEAK_SIGMAS times that.
    n_used = np.maximum(np.sum(~view.masked, axis=1), 1)
    threshold = np.maximum(3.0, FALSE_PEAK_SIGMAS * np.maximum(NOISE_SD_DB / np.sqrt(n_used), 0.2))
    lines, cleaned = _find_lines(view, threshold, orders)
    shape = _cut_lines(f, view.shape, lines)
    modes = _find_modes(view, cleaned, shape, threshold, orders, lines)
    return ModalSurvey("runup", tuple(modes), tuple(lines), tuple(orders), (fmin, fmax), float(df), f[band],
                       view.stationary[band], slice_speed=view.speed, spectrogram_db=view.norm[band],
                       notes=tuple(notes))


def _smooth121(v: np.ndarray) -> np.ndarray:
    """[1 2 1]/4 smoothing: keeps humps and lines (>= 1.4 bins wide under Hann), takes the edge off
    bin-to-bin estimation noise."""
    return np.convolve(np.pad(v, 1, mode="edge"), [0.25, 0.5, 0.25], mode="valid")


class _View:
    """One spectrogram of the record and what is read from it (see the module docstring)."""

    @classmethod
    def of(cls, x, fs, nperseg, angle, fmin, fmax) -> "_View":
        v = cls()
        v.f, power, starts = _slices(x, fs, nperseg)
        v.df = v.f[1] - v.f[0]
        v.raw = 10 * np.log10(np.maximum(power, np.finfo(float).tiny))
        v.norm = v.raw - _local_floor(v.raw, v.f, fmin, fmax)
        v.inband = (v.f >= fmin) & (v.f <= fmax)
        v.band = np.flatnonzero(v.inband)
        v.speed = v.spread = None
        if angle is not None:
            v.speed, v.spread = _slice_speeds(angle, starts, nperseg, fs)
            if np.any(v.speed <= 0):
                raise SignalError("the shaft angle must increase (a speed <= 0 Hz was found in the record)")
        return v

    def mask(self, orders) -> None:
        """Mask the orders' tracks; set ``stationary`` (dB re local floor, smoothed) and ``shape``."""
        if self.speed is None or not orders:
            self.masked = np.zeros(self.raw.shape, dtype=bool)
        else:
            self.masked = _mask_orders(self.raw.shape, self.f, self.speed, self.spread, orders)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            stationary = np.nanmedian(np.where(self.masked, np.nan, self.norm), axis=1)
            # the same without the local floor's tilt (each slice shifted by one constant): the
            # shape of a hump as the sensor saw it, for the fit of frequency and damping
            flat = self.raw - np.median(self.raw[self.inband], axis=0)[None, :]
            shape = np.nanmedian(np.where(self.masked, np.nan, flat), axis=1)
        gaps = ~np.isfinite(stationary)
        if gaps.all():
            raise SignalError("every bin is covered by an order track; nothing stationary is left")
        for arr in (stationary, shape):
            arr[gaps] = np.interp(self.f[gaps], self.f[~gaps], arr[~gaps])
        self.stationary = _smooth121(stationary)
        self.shape = _smooth121(shape)
