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

Frequencies in Hz, angles in rad, levels in dB re the local floor.
"""
from __future__ import annotations

import warnings

import numpy as np
from scipy import signal as sps
from scipy.optimize import least_squares

from twin.signals._checks import SignalError, as_signal, positive, same_length
from twin.signals.survey import Line, ModalSurvey, Mode, Order

#: Robust (MAD-based) sd [dB] of one periodogram bin of a Gaussian random process about a fitted
#: trend (a log-exponential variable: 5.0 dB, a little less once the trend is fitted).
RANDOM_BIN_SD_DB = 4.6
#: -3 dB width of a sinusoid's peak under a Hann window, in bins, off-bin worst case about 2.
LINE_WIDTH_BINS = 2.5
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


def _robust_sd(v: np.ndarray) -> float:
    v = v[np.isfinite(v)]
    if v.size < 3:
        return float("nan")
    return float(1.4826 * np.median(np.abs(v - np.median(v))))


def _fluctuation_db(raw_db: np.ndarray, masked: np.ndarray, k: int) -> float:
    """Robust sd [dB] of bin k's level over the unmasked slices, about a quadratic trend in time."""
    v = raw_db[k].copy()
    v[masked[k]] = np.nan
    t = np.arange(v.size, dtype=float)
    ok = np.isfinite(v)
    if ok.sum() < 5:
        return float("nan")
    coef = np.polyfit(t[ok], v[ok], 2)
    return _robust_sd(v[ok] - np.polyval(coef, t[ok]))


def _half_power_width(f: np.ndarray, z: np.ndarray, k: int) -> float:
    """-3 dB width [Hz] of the peak at bin k of a dB spectrum (inf if it never falls 3 dB)."""
    target = z[k] - 3.0103
    edges = []
    for step in (-1, 1):
        i = k
        while 0 <= i + step < z.size and z[i + step] > target:
            i += step
        j = i + step
        if not 0 <= j < z.size:
            return float("inf")
        edges.append(f[i] + (z[i] - target) / (z[i] - z[j]) * (f[j] - f[i]))
    return float(edges[1] - edges[0])


_KERNEL_STEP = 0.125
_KERNEL_OFFSETS = np.arange(-4.0, 4.0 + _KERNEL_STEP / 2, _KERNEL_STEP)


def _hann_power_kernel(delta: np.ndarray) -> np.ndarray:
    """|W(delta)|^2 of the Hann window at ``delta`` bins from a line, normalised to unit sum."""
    with np.errstate(divide="ignore", invalid="ignore"):
        w = np.sinc(delta) / (1.0 - delta ** 2)
    w[np.isclose(np.abs(delta), 1.0)] = 0.5
    k = w ** 2
    return k / k.sum()


_KERNEL = _hann_power_kernel(_KERNEL_OFFSETS)


def _sdof_fit(f: np.ndarray, z: np.ndarray, k: int, lo: int, hi: int, df: float
              ) -> tuple[float, float, float, float]:
    """Single-mode fit of a hump in a dB spectrum over bins [lo, hi): (fn [Hz], zeta, R^2, sd of fn [Hz]).

    Model: 10 log10(a^2 |1 / (1 - r^2 + 2j zeta r) + beta|^2 + n), r = f / fn, seen through the
    Hann window (the model power is convolved with the window's power kernel before it is
    compared with the bins, so a hump narrower than a bin still gives its centre). ``beta`` is
    the other modes' contribution near this one, nearly real away from their own resonances (in
    or out of phase); it shifts the response peak away from the natural frequency, by up to a few
    per cent when modes are close, so it is fitted rather than ignored. ``n`` is the floor of
    incoherent content. ``zeta`` is NaN when the hump is not resolved (narrower than a bin).
    """
    ff, zz = f[lo:hi], z[lo:hi]
    if ff.size < 6:
        return float(f[k]), float("nan"), 0.0, float(df)
    fpk = f[k]
    width = _half_power_width(f, z, k)
    zeta0 = float(np.clip(width / (2 * fpk) if np.isfinite(width) else 0.02, 2e-3, 0.2))
    peak = 10 ** (z[k] / 10)
    floor0 = max(10 ** (np.min(zz) / 10), peak * 1e-6)
    la0 = np.log10(max(peak - floor0, peak * 1e-3) * (2 * zeta0) ** 2)
    grid = ff[:, None] + _KERNEL_OFFSETS[None, :] * df

    def model(p):
        fn, zeta, la, beta, ln = p
        r = grid / fn
        h = 1.0 / (1 - r * r + 2j * zeta * r) + beta
        return 10 * np.log10((10 ** la * np.abs(h) ** 2) @ _KERNEL + 10 ** ln)

    reach = max(3 * df, 2 * zeta0 * fpk)
    p0 = np.array([_parabolic(f, z, k), zeta0, la0, 0.0, np.log10(floor0)])
    lb = np.array([fpk - reach, 1e-4, la0 - 6, -0.25 / zeta0, p0[4] - 6])
    ub = np.array([fpk + reach, 0.3, la0 + 6, 0.25 / zeta0, p0[4] + 3])
    p0 = np.clip(p0, lb + 1e-9, ub - 1e-9)
    sol = least_squares(lambda p: model(p) - zz, p0, bounds=(lb, ub), x_scale=[df, 0.01, 1.0, 1.0, 1.0])
    ss = float(np.sum((zz - zz.mean()) ** 2)) or 1.0
    r2 = 1.0 - float(np.sum(sol.fun ** 2)) / ss
    fn, zeta = float(sol.x[0]), float(sol.x[1])
    # standard error of fn from the fit's Jacobian and residual scatter (bins are correlated by
    # the window and the smoothing, about 3 to one independent value, hence the factor)
    dof = max(ff.size - 5, 1)
    try:
        cov = np.linalg.pinv(sol.jac.T @ sol.jac) * (float(np.sum(sol.fun ** 2)) / dof) * 3.0
        fn_sd = float(np.sqrt(max(cov[0, 0], 0.0)))
    except np.linalg.LinAlgError:
        fn_sd = float(df)
    # a half-power band narrower than half a bin is not resolved by these slices
    return fn, (zeta if 2 * zeta * fn >= 0.5 * df else float("nan")), r2, max(fn_sd, 0.05 * df)


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


def _cut_lines(f: np.ndarray, z: np.ndarray, lines) -> np.ndarray:
    """z with each line's bins replaced by a straight line between its neighbours (see _line_cuts)."""
    out = z.copy()
    for lo, hi in _line_cuts(f, z, lines):
        out[lo:hi] = np.interp(f[lo:hi], [f[lo - 1], f[hi]], [out[lo - 1], out[hi]])
    return out


def _line_cuts(f: np.ndarray, z: np.ndarray, lines) -> list[tuple[int, int]]:
    """Bins [lo, hi) each line of a dB spectrum z covers.

    The cut is as wide as the line's window leakage reaches above the level around it: a
    line 40 dB above a resonance hump leaks over +-5 bins of a Hann window, one 10 dB above it
    over +-2.
    """
    df = f[1] - f[0]
    cuts = []
    for ln in lines:
        p = int(round(ln.frequency / df))
        if not 1 <= p < f.size - 1:
            continue
        height = max(_excess_db(z, p), 0.0)
        reach = _KERNEL_OFFSETS[_KERNEL_OFFSETS >= 0]
        leak = 10 * np.log10(np.maximum(_KERNEL[_KERNEL_OFFSETS >= 0] / _KERNEL.max(), 1e-30)) + height
        h = int(np.ceil(reach[np.flatnonzero(leak > 0.0)].max() if (leak > 0.0).any() else 1.0))
        h = max(2, min(h + 1, 8))
        cuts.append((max(p - h, 1), min(p + h + 1, f.size - 1)))
    return cuts


def _shaft_harmonic(fc: float, speed, df: float) -> float | None:
    """The integer order at fc for a (nearly) constant speed, if fc sits on one; else None."""
    if speed is None:
        return None
    s = float(np.median(speed))
    k = round(fc / s)
    if k >= 1 and abs(fc - k * s) <= 1.5 * df + 0.5 * k * float(np.ptp(speed)):
        return float(k)
    return None


def _parabolic(f, z, k) -> float:
    if 0 < k < z.size - 1:
        a, b, c = z[k - 1], z[k], z[k + 1]
        den = a - 2 * b + c
        if den < 0:
            return float(f[k] + 0.5 * (a - c) / den * (f[1] - f[0]))
    return float(f[k])


def _excess_db(z: np.ndarray, k: int) -> float:
    """Height [dB] of bin k above its neighbourhood (bins 3-8 away on both sides)."""
    near = np.r_[z[max(k - 8, 0):max(k - 2, 0)], z[k + 3:k + 9]]
    return float(z[k] - np.median(near)) if near.size else 0.0


def _steadiness(raw, masked, z, k) -> tuple[bool, float, float]:
    """Is the narrow peak at bin k deterministic? (steady, measured sd [dB], sd a line would have [dB]).

    A line of power A^2 over random content of power N in its bin fluctuates by about
    6.14 / sqrt(A^2 / N) dB from slice to slice; a randomly excited bin by about 4.6 dB (robust
    sd of a log-exponential variable about a fitted trend). The peak is taken as steady when its
    measured fluctuation is nearer (geometrically) to the line's than to the random bin's.
    """
    fluct = _fluctuation_db(raw, masked, k)
    snr = 10 ** (max(_excess_db(z, k), 0.0) / 10)
    line_sd = min(6.14 / np.sqrt(max(snr - 1.0, 1e-3)), RANDOM_BIN_SD_DB)
    limit = float(np.sqrt(line_sd * RANDOM_BIN_SD_DB))
    return bool(np.isfinite(fluct) and fluct < limit), fluct, line_sd


def _find_lines(view: _View, threshold: np.ndarray, orders) -> tuple[list[Line], np.ndarray]:
    """Narrow, steady peaks; returns (lines, stationary spectrum with the lines cut out)."""
    f, z, df = view.f, view.stationary, view.df
    lines = []
    peaks, props = sps.find_peaks(z[view.band], prominence=0.0)
    for p in view.band[peaks[props["prominences"] >= threshold[view.band[peaks]]]]:
        width = _half_power_width(f, z, p)
        if width > LINE_WIDTH_BINS * df:
            continue
        steady, fluct, line_sd = _steadiness(view.raw, view.masked, z, p)
        if not steady:
            continue
        fc = _parabolic(f, z, p)
        if not orders and _shaft_harmonic(fc, view.speed, df) is not None:
            lines.append(Line(fc, float(z[p]), float(width), {"shaft_harmonic": True}))
            continue
        lines.append(Line(fc, float(z[p]), float(width),
                          {"slice_level_sd_db": round(fluct, 2), "line_sd_db": round(line_sd, 2),
                           "width_bins": round(float(width / df), 2),
                           "reason": "narrow, fixed in frequency and steady from slice to slice (deterministic)"}))
    cleaned = _cut_lines(f, z, lines)
    return [ln for ln in lines if not ln.evidence.get("shaft_harmonic")], cleaned


def _crossing_orders(fn: float, speed, orders) -> list[float]:
    if speed is None:
        return []
    return [o.order for o in orders if o.order * speed.min() < fn < o.order * speed.max()]


def _find_modes(view: _View, cleaned: np.ndarray, shape: np.ndarray, threshold: np.ndarray, orders,
                lines) -> list[Mode]:
    """Resonances: every peak of the line-free stationary spectrum that is not narrow and steady."""
    f, df, band = view.f, view.df, view.band
    peaks, props = sps.find_peaks(cleaned[band], prominence=0.0)
    keep = props["prominences"] >= threshold[band[peaks]]
    idx = band[peaks[keep]]
    prominence = props["prominences"][keep]
    modes = []
    for j, (p, prom) in enumerate(zip(idx, prominence)):
        width = _half_power_width(f, cleaned, p)
        narrow = np.isfinite(width) and width <= LINE_WIDTH_BINS * df
        if narrow:
            steady, fluct, _ = _steadiness(view.raw, view.masked, cleaned, p)
            if steady:
                continue    # narrow and steady: a line, not a mode
        else:
            fluct = _fluctuation_db(view.raw, view.masked, p)
        # fit window: the hump, limited to half-way to the neighbouring peaks
        reach = int(np.clip(np.ceil(2.5 * (width if np.isfinite(width) else 4 * df) / df), 4, 200))
        lo = max(p - reach, (idx[j - 1] + p) // 2 if j > 0 else band[0], 1)
        hi = min(p + reach + 1, (idx[j + 1] + p) // 2 + 1 if j + 1 < idx.size else band[-1] + 1)
        fn, zeta, r2, fn_sd = _sdof_fit(f, shape, p, lo, hi, df)
        unmasked = ~view.masked[p]
        present = float(np.mean(view.norm[p, unmasked] > 0.5 * prom)) if unmasked.any() else 0.0
        # confidence: how far the hump clears the noise of the spectrum, how often it is there,
        # how well one mode explains its shape; a narrow random peak is a weaker case than a hump
        clear = 1.0 - np.exp(-((prom / (2.0 * threshold[p])) ** 2))
        conf = clear * (0.4 + 0.6 * present) * (0.6 + 0.4 * max(r2, 0.0)) * (0.7 if narrow else 1.0)
        evidence = {"width_hz": round(float(width), 3) if np.isfinite(width) else None,
                    "slice_level_sd_db": round(float(fluct), 2) if np.isfinite(fluct) else None,
                    "persistence": round(present, 3), "fit_r2": round(r2, 3),
                    "frequency_sd_hz": round(fn_sd, 3), "resolution_hz": round(float(df), 4),
                    "orders_crossing": _crossing_orders(fn, view.speed, orders),
                    "reason": ("a hump wider than a line, fixed in frequency" if not narrow else
                               "narrow but random from slice to slice: a lightly damped resonance")}
        reach_hz = max(3 * df, 3 * width if np.isfinite(width) else 0.0)
        near = [ln.frequency for ln in lines if abs(ln.frequency - fn) <= reach_hz]
        if near:
            evidence["line_on_top_hz"] = [round(v, 2) for v in near]
        modes.append(Mode(float(fn), float(zeta), float(np.clip(conf, 0.0, 1.0)), float(prom), evidence))
    return sorted(modes, key=lambda m: m.frequency)
